"""``ballbot.gym``: Gymnasium's own checker on every registered environment, seeded rollouts,
randomisation through ``reset(options=...)``, the stop rules (``stop_on``) and the contact
events in ``info``, rendering, and the native vector env against ``SyncVectorEnv`` bit for
bit."""

import json
import pickle
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import AutoresetMode

import ballbot
import ballbot.gym
from ballbot.gym import ENV_IDS, BallbotEnv, BallbotVectorEnv


@pytest.mark.filterwarnings("error")  # the checker's warnings count as failures
@pytest.mark.parametrize("env_id", sorted(ENV_IDS))
def test_gymnasium_check_env_passes(env_id: str) -> None:
    for mode in (None, "rgb_array", "ansi"):
        env = gym.make(env_id, render_mode=mode)
        check_env(env.unwrapped, skip_render_check=mode is None)
        env.close()


def scripted(obs: np.ndarray) -> np.ndarray:
    """Leans the wheels against the tilt: a crude policy that reacts to the observation."""
    roll, pitch = float(obs[0]), float(obs[1])
    return np.array([0.3 * pitch, -0.2 * roll, 0.1 * roll], dtype=np.float32)


def rollout(env: gym.Env[Any, Any], seed: int, steps: int) -> list[tuple[Any, ...]]:
    obs, info = env.reset(seed=seed)
    out: list[tuple[Any, ...]] = [(obs.tobytes(), info["episode_seed"])]
    for _ in range(steps):
        obs, r, term, trunc, _ = env.step(scripted(obs))
        out.append((obs.tobytes(), r, term, trunc))
        if term or trunc:
            break
    return out


def test_a_seed_replays_and_an_unseeded_episode_reports_its_seed() -> None:
    env = gym.make("ballbot/Balance-v0", randomization="recommended")
    assert rollout(env, 3, 150) == rollout(env, 3, 150)
    assert rollout(env, 3, 150) != rollout(env, 4, 150)
    env.reset(seed=3)
    _, info = env.reset()  # the next episode of seed 3's stream
    replay = rollout(env, info["episode_seed"], 50)
    env.reset(seed=3)
    env.reset()
    obs, _ = env.unwrapped.reset(seed=info["episode_seed"])
    assert obs.tobytes() == replay[0][0]


def test_balance_terminates_on_a_fall_and_velocity_truncates_at_the_time_limit() -> None:
    env = gym.make("ballbot/Balance-v0")
    env.reset(seed=0, options={"initial_tilt_rad": [0.0, 0.1]})
    for k in range(1000):
        _, _, term, trunc, info = env.step(np.zeros(3, dtype=np.float32))
        if term or trunc:
            break
    assert term and not trunc
    assert info["failure"].kind == ballbot.FailureKind.TILT
    assert info["termination"] == "tilt"
    assert isinstance(info["episode_events"], list) and info["events_dropped"] == 0
    with pytest.raises(ballbot.BallbotError, match="reset"):
        env.step(np.zeros(3, dtype=np.float32))
    # The LQR-PI underneath, no residual: stays up until the time limit.
    env = gym.make("ballbot/Velocity-v0", max_episode_secs=1.0)
    env.reset(seed=1, options={"command": [0.3, 0.0, 0.0]})
    total = 0.0
    for k in range(1000):
        obs, r, term, trunc, info = env.step(np.zeros(3, dtype=np.float32))
        total += r
        if term or trunc:
            break
    assert trunc and not term and k == 399
    assert info["termination"] is None and "episode_events" in info
    assert total > 0.8 * 400
    assert obs[9] == pytest.approx(0.3)


def test_randomisation_options_reach_the_episode_and_bad_ones_name_the_key() -> None:
    env = gym.make("ballbot/Balance-v0")
    nominal = env.unwrapped.core.params.robot.sagittal.body_mass_kg
    _, info = env.reset(seed=0, options={"randomization": {"added_payload_kg": 10.0}})
    assert info["params"].robot.sagittal.body_mass_kg == pytest.approx(nominal + 10.0)
    assert info["draw"]["added_payload_kg"] == 10.0
    _, info = env.reset(seed=0)
    assert info["params"].robot.sagittal.body_mass_kg == nominal
    with pytest.raises(ballbot.ParameterError, match="unknown field `mu`"):
        env.reset(options={"randomization": {"mu": 0.5}})
    with pytest.raises(ballbot.ParameterError, match="unknown reset option `payload`"):
        env.reset(options={"payload": 1})
    with pytest.raises(ballbot.ParameterError, match="randomization.com_height_m"):
        gym.make("ballbot/Balance-v0", randomization={"com_height_m": [0.5, 0.1]})
    with pytest.raises(ballbot.ParameterError, match="control_hz"):
        gym.make("ballbot/Balance-v0", control_hz=333.0)
    with pytest.raises(ballbot.ParameterError, match="arming tilt"):
        gym.make("ballbot/Velocity-v0", randomization={"initial_tilt_rad": [0.0, 0.1]})


def test_the_observation_can_carry_the_last_action_and_the_rate_can_change() -> None:
    env = gym.make("ballbot/Balance-v0", last_action_in_observation=True, control_hz=100.0)
    assert env.observation_space.shape == (15,)
    assert env.unwrapped.core.steps_per_action == 80
    env.reset(seed=0)
    obs, *_ = env.step(np.array([0.5, -0.25, 2.0], dtype=np.float32))
    assert obs[12:].tolist() == [0.5, -0.25, 1.0]  # clipped to the box
    _, _, _, _, info = env.step(np.zeros(3, dtype=np.float32))
    assert info["time_secs"] == pytest.approx(0.02)


# Exact colours of the renderer (crates/ballbot-render/src/palette.rs): the inside of a
# filled shape is exactly its colour.
LIFT_OFF = (222, 28, 40)
WHEELS = [(40, 52, 96), (34, 82, 56), (92, 44, 78)]


def count(frame: np.ndarray, rgb: tuple[int, int, int]) -> int:
    return int(np.all(frame == rgb, axis=-1).sum())


def edited(t: ballbot.StepTelemetry, edit: Any) -> ballbot.StepTelemetry:
    """``t`` with its record changed by ``edit(dict)`` (through the pickled JSON)."""
    rebuild, (cls, text) = t.__reduce__()
    data = json.loads(text)
    edit(data)
    return rebuild(cls, json.dumps(data))


def test_rendering_draws_the_robot_its_wheels_and_no_lift_off() -> None:
    env = gym.make("ballbot/Balance-v0", render_mode="rgb_array")
    env.reset(seed=0)
    for _ in range(5):
        env.step(np.zeros(3, dtype=np.float32))
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.shape == (360, 480, 3)
    # The three omniwheels, each in its colour, and no wheel lifted.
    assert [count(frame, c) > 60 for c in WHEELS] == [True] * 3
    assert count(frame, LIFT_OFF) == 0
    text = gym.make("ballbot/Balance-v0", render_mode="ansi")
    text.reset(seed=0)
    assert "tilt=" in text.render()


def test_a_lifted_wheel_shows_red_where_a_balanced_frame_has_none() -> None:
    env = gym.make("ballbot/Balance-v0", render_mode="rgb_array")
    env.reset(seed=0)
    env.step(np.zeros(3, dtype=np.float32))
    t = env.unwrapped.core.telemetry
    renderer = ballbot.SceneRenderer(env.unwrapped.core.params)
    balanced = renderer.render(t)

    def lift_ow2(d: dict[str, Any]) -> None:
        d["wheels"][1]["normal_force_n"] = 0.0
        d["wheels"][1]["cone_utilisation"] = 0.0

    lifted = renderer.render(edited(t, lift_ow2))
    assert count(balanced, LIFT_OFF) == 0
    assert count(lifted, LIFT_OFF) > 200
    # OW2 is drawn red instead of its own colour; OW1 and OW3 are unchanged.
    assert count(lifted, WHEELS[1]) == 0 and count(balanced, WHEELS[1]) > 60
    assert count(lifted, WHEELS[0]) == count(balanced, WHEELS[0])
    assert renderer.png(t)[1:4] == b"PNG"


def test_the_floor_grid_shifts_when_the_ball_moves() -> None:
    env = gym.make("ballbot/Balance-v0")
    env.reset(seed=0)
    t = env.unwrapped.core.telemetry
    renderer = ballbot.SceneRenderer()

    def moved(dx: float) -> ballbot.StepTelemetry:
        def edit(d: dict[str, Any]) -> None:
            d["ball_position_m"][0] += dx
            d["body_position_m"][0] += dx

        return edited(t, edit)

    still = renderer.render(t).astype(int)
    # The camera follows the robot: a quarter tile moves the floor under it, a whole
    # checker period (two 0.5 m tiles) gives the same picture again.
    quarter = int(np.any(renderer.render(moved(0.125)) != still, axis=-1).sum())
    period = int(np.any(renderer.render(moved(1.0)) != still, axis=-1).sum())
    assert quarter > 10_000
    assert period < quarter / 10
    with pytest.raises(ballbot.ParameterError, match="frame size"):
        ballbot.SceneRenderer(width=4)


def test_the_vector_env_renders_a_frame_per_environment() -> None:
    envs = BallbotVectorEnv(num_envs=2, render_mode="rgb_array")
    envs.reset(seed=3)
    envs.step(np.zeros((2, 3), dtype=np.float32))
    frames = envs.render()
    assert frames is not None and len(frames) == 2
    assert all(f.shape == (360, 480, 3) and f.dtype == np.uint8 for f in frames)
    assert [count(frames[1], c) > 60 for c in WHEELS] == [True] * 3
    envs.close()


def test_human_mode_needs_matplotlib_and_says_so() -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
    except ImportError:
        assert "human" not in BallbotEnv.metadata["render_modes"]
        with pytest.raises(ImportError, match="matplotlib"):
            BallbotEnv(render_mode="human")
        return
    assert "human" in BallbotEnv.metadata["render_modes"]
    env = gym.make("ballbot/Balance-v0", render_mode="human")
    env.reset(seed=0)
    env.step(np.zeros(3, dtype=np.float32))
    assert env.render() is None
    env.close()


def test_make_vec_gives_the_native_vector_env() -> None:
    envs = gym.make_vec("ballbot/Balance-v0", num_envs=4, vectorization_mode="vector_entry_point")
    assert isinstance(envs.unwrapped, BallbotVectorEnv)
    assert envs.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    obs, infos = envs.reset(seed=10)
    assert obs.shape == (4, 12) and obs.dtype == np.float32
    assert infos["episode_seed"].tolist() == [10, 11, 12, 13]
    obs, r, term, trunc, infos = envs.step(envs.action_space.sample())
    assert r.shape == (4,) and term.dtype == bool and infos["_time_secs"].all()
    assert envs.observation_space.contains(obs)
    envs.close()


@pytest.mark.parametrize("task", ["balance", "velocity"])
def test_the_native_vector_env_equals_sync_vector_env_bit_for_bit(task: str) -> None:
    n, steps = 3, 400
    kwargs: dict[str, Any] = {"task": task, "max_episode_secs": 0.25, "randomization": "recommended"}
    native = BallbotVectorEnv(num_envs=n, threads=2, **kwargs)
    sync = gym.vector.SyncVectorEnv([lambda: BallbotEnv(**kwargs) for _ in range(n)])
    rng = np.random.default_rng(0)
    actions = rng.uniform(-1, 1, size=(steps, n, 3)).astype(np.float32)
    a_obs, _ = native.reset(seed=5)
    b_obs, _ = sync.reset(seed=5)
    assert np.array_equal(a_obs, b_obs)
    resets = events = 0
    for k in range(steps):
        a = native.step(actions[k])
        b = sync.step(actions[k])
        for x, y in zip(a[:4], b[:4]):
            assert np.array_equal(x, y), k
        resets += int(a[4]["_episode_seed"].sum())
        # The infos the single environments give, per environment where it gave them.
        for key in ("events", "termination", "episode_events", "events_dropped"):
            assert key_values(a[4], key, n) == key_values(b[4], key, n), (k, key)
        events += sum(len(e) for e in key_values(a[4], "events", n) if e)
    assert resets >= n, "every environment ended and was autoreset"
    if task == "balance":
        assert events > 0, "the random torques make contact events"


def key_values(infos: dict[str, Any], key: str, n: int) -> list[Any]:
    """A vector info's values for ``n`` environments where set (``None`` elsewhere)."""
    if key not in infos:
        return [None] * n
    return [v if m else None for v, m in zip(infos[key].tolist(), infos["_" + key])]


LEAN = np.array([0.5, -0.5, 0.0], dtype=np.float32)


def lean_and_let_go(**kwargs: Any) -> list[tuple[bool, bool, dict[str, Any]]]:
    """Balance from upright (seed 0): opposite torques on OW1 and OW2 for ten steps, then
    nothing, until the episode ends (the Rust test's scenario, ``tests/gym.rs``)."""
    env = gym.make("ballbot/Balance-v0", **kwargs)
    env.reset(seed=0, options={"initial_tilt_rad": [0.0, 0.0]})
    out = []
    for k in range(2000):
        action = LEAN if k < 10 else np.zeros(3, dtype=np.float32)
        _, _, term, trunc, info = env.step(action)
        out.append((term, trunc, info))
        if term or trunc:
            break
    return out


def test_a_lift_off_is_an_event_by_default_and_stop_on_all_ends_the_episode_on_it() -> None:
    old = lean_and_let_go(stop_on="all")
    term, _, info = old[-1]
    k = len(old) - 1
    assert term and info["termination"] == "lift_off" and k < 20
    assert info["failure"].kind == ballbot.FailureKind.LIFT_OFF
    wheel = info["failure"].wheel

    new = lean_and_let_go()
    term, trunc, info = new[k]
    assert not term and not trunc and info["termination"] is None and info["failure"] is None
    lift_offs = [e for e in info["events"] if e["kind"] == "lift_off" and e["wheel"] == wheel]
    assert len(lift_offs) == 1, info["events"]
    e = lift_offs[0]
    assert e["ongoing"] and e["duration_secs"] > 0.02
    assert e["onset_secs"] < info["time_secs"] and e["min_normal_force_n"] < 1.0
    keys = {"kind", "wheel", "min_normal_force_n", "onset_secs", "duration_secs", "ongoing"}
    assert set(e) == keys
    assert "episode_events" not in info, "the whole log only at the episode's end"
    assert len(new) > k + 50, "the episode goes on"
    term, _, end = new[-1]
    assert term and end["termination"] in ("tilt", "fell")
    # The log at the end has the lift-off, as it was when it ended.
    ended = [x for x in end["episode_events"] if x["onset_secs"] == e["onset_secs"]]
    assert ended and not ended[0]["ongoing"] and ended[0]["duration_secs"] > e["duration_secs"]
    assert end["events_dropped"] == 0
    kinds = {x["kind"] for x in end["episode_events"]}
    assert kinds <= {"slip", "lift_off", "driver_trip"}, "no controller underneath"


def test_stop_on_takes_the_cli_rules_names_them_back_and_rejects_others() -> None:
    assert BallbotEnv().stop_on == "tilt,driver-trip"
    assert BallbotEnv(stop_on="all").stop_on == "tilt,slip,lift-off,driver-trip"
    assert BallbotEnv(stop_on="none").stop_on == "none"
    assert BallbotEnv(stop_on=["slip", "lift-off"]).stop_on == "slip,lift-off"
    assert BallbotEnv(stop_on=[]).stop_on == "none"
    assert BallbotVectorEnv(num_envs=2, stop_on="tilt").stop_on == "tilt"
    with pytest.raises(ballbot.ParameterError, match="stop_on.*unknown stop rule `wobble`"):
        BallbotEnv(stop_on="slip,wobble")
    with pytest.raises(ballbot.ParameterError, match="stop_on.*unknown stop rule `lift_off`"):
        BallbotEnv(stop_on=["lift_off"])
    with pytest.raises(ballbot.ParameterError, match="stop_on"):
        BallbotEnv(stop_on=3)  # type: ignore[arg-type]
    with pytest.raises(ballbot.ParameterError, match="stop_on"):
        BallbotVectorEnv(num_envs=2, stop_on="wobble")


def test_stop_on_survives_the_env_spec_round_trips() -> None:
    env = gym.make("ballbot/Balance-v0", stop_on="slip,lift-off")
    assert env.spec is not None and env.spec.kwargs["stop_on"] == "slip,lift-off"
    from_json = gym.envs.registration.EnvSpec.from_json(env.spec.to_json())
    for spec in (pickle.loads(pickle.dumps(env.spec)), from_json):
        again = gym.make(spec)
        assert again.unwrapped.stop_on == "slip,lift-off"
    envs = gym.make_vec(
        "ballbot/Balance-v0", num_envs=2, vectorization_mode="vector_entry_point", stop_on="none"
    )
    assert envs.unwrapped.stop_on == "none"
