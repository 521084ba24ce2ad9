
# %% [markdown]
# The 3D scene, the frame transforms, the wheel joints and the event log are Foxglove's own
# messages (protobuf, from the official Foxglove SDK). `McapLog` decodes them too, with
# Foxglove's field names, so the wheel angles come out as columns of `/joint_states`:

# %%
joints = log.numeric_series("/joint_states")
print(sorted(joints))
print(np.allclose(joints["joints[0].position"][-1], run.wheel_angle_rad[-1, 0], atol=0.5))

# %% [markdown]
# Any MCAP tool reads the file as well. With `pip install "ballbot[mcap]"`, the `mcap` package
# and `mcap-protobuf-support` decode the same messages from the schemas the file carries:

# %%
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

with open(path, "rb") as f:
    reader = make_reader(f, decoder_factories=[DecoderFactory()])
    angles = np.array(
        [
            [j.position for j in msg.joints]
            for _, _, _, msg in reader.iter_decoded_messages(topics=["/joint_states"])
        ]
    )
print(angles.shape, "wheel angles at 100 Hz")
print(np.array_equal(angles[:, 0], joints["joints[0].position"]))
