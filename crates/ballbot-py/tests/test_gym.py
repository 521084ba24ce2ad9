"""``ballbot.gym``: Gymnasium's own checker on every registered environment, seeded rollouts,
randomisation through ``reset(options=...)``, rendering, and the native vector env against
``SyncVectorEnv`` bit for bit."""

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


def test_rendering_draws_the_robot() -> None:
    env = gym.make("ballbot/Balance-v0", render_mode="rgb_array")
    env.reset(seed=0, options={"initial_tilt_rad": [0.0, 0.15]})
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.shape == (240, 482, 3)
    blue = np.all(frame == (40, 70, 160), axis=-1)
    red = np.all(frame == (200, 60, 50), axis=-1)
    assert blue.sum() > 100 and red.sum() > 100
    # Tilted about world y towards +x: in the first view the body leans right of the ball.
    rows, cols = np.nonzero(blue[:, :240])
    top_col = cols[rows == rows.min()].mean()
    ball_col = np.nonzero(red[:, :240])[1].mean()
    assert top_col > ball_col + 10
    # The second view looks along x: upright there.
    rows, cols = np.nonzero(blue[:, 242:])
    assert abs(cols[rows == rows.min()].mean() - np.nonzero(red[:, 242:])[1].mean()) < 2
    text = gym.make("ballbot/Balance-v0", render_mode="ansi")
    text.reset(seed=0)
    assert "tilt=" in text.render()


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
    resets = 0
    for k in range(steps):
        a = native.step(actions[k])
        b = sync.step(actions[k])
        for x, y in zip(a[:4], b[:4]):
            assert np.array_equal(x, y), k
        resets += int(a[4]["_episode_seed"].sum())
    assert resets >= n, "every environment ended and was autoreset"
