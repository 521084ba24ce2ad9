"""``ballbot.gym.pretrained("balance")``: the shipped policy stands seeded episodes it was not
selected on, a policy made wrong falls on the same episodes (so the standing count can fail),
and the policy file's checks."""

import json
from pathlib import Path

import numpy as np
import pytest

import ballbot.gym
from ballbot.gym import Policy, evaluate, pretrained

# Not the training's evaluation seeds (10,000 to 10,019), which chose the shipped policy.
SEEDS = list(range(20))


# Each policy where docs/gym.md's held-out evaluation has it stand 100 of 100: `balance` on its
# task (initial tilts up to 0.1 rad); `balance_randomized` with the campaign's ranges (its own
# environment) from tilts up to 0.045 rad.
CONDITIONS = {"balance": None, "balance_randomized": {"randomization": {"initial_tilt_rad": [0.0, 0.045]}}}


@pytest.mark.parametrize("name", sorted(ballbot.gym.PRETRAINED))
def test_the_pretrained_policies_stand_twenty_seeded_episodes(name: str) -> None:
    policy = pretrained(name)
    # Short episodes in the test command, on the policy's own environment; the docs' 10 s
    # evaluation is examples/python/evaluate_balance.py's.
    result = evaluate(policy, SEEDS, options=CONDITIONS[name], max_episode_secs=2.0)
    print(f"{name}, seeds {SEEDS[0]} to {SEEDS[-1]}: {result['standing']} of 20 standing")
    assert result["standing"] == 20, result["episodes"]
    # Balanced, not just alive: the tilt settles well below the initial tilts (up to 0.1 rad).
    assert result["mean_abs_tilt_deg"] < 3.0


def test_a_policy_made_wrong_falls_on_the_same_episodes() -> None:
    policy = pretrained("balance")
    flipped = Policy(
        weights=-policy.weights, obs_mean=policy.obs_mean, obs_std=policy.obs_std, env_id=policy.env_id
    )
    result = evaluate(flipped, SEEDS[:8], max_episode_secs=2.0)
    assert result["standing"] == 0, result["episodes"]
    zero = Policy(weights=np.zeros_like(policy.weights), obs_mean=policy.obs_mean, obs_std=policy.obs_std)
    assert evaluate(zero, SEEDS[:8], max_episode_secs=2.0)["standing"] == 0


def test_the_policy_file_round_trips_and_bad_ones_are_refused(tmp_path: Path) -> None:
    policy = pretrained("balance")
    assert policy.env_id == "ballbot/Balance-v0"
    assert policy.trained["command"].startswith("python examples/python/train_balance_ars.py")
    path = tmp_path / "p.json"
    policy.save(path)
    again = Policy.load(path)
    obs = np.linspace(-0.1, 0.1, policy.weights.shape[1])
    assert np.array_equal(again(obs), policy(obs))
    assert policy(np.stack([obs, obs])).shape == (2, 3)
    with pytest.raises(ValueError, match=r"entry \(3,\) is not finite"):
        policy(np.where(np.arange(len(obs)) == 3, np.nan, obs))
    with pytest.raises(ValueError, match="must end in"):
        policy(obs[:5])
    d = json.loads(path.read_text())
    with pytest.raises(ValueError, match="not a policy file"):
        Policy.from_dict({**d, "format": "other"})
    with pytest.raises(ValueError, match="`obs_std` must be > 0"):
        Policy.from_dict({**d, "obs_std": [0.0] * len(d["obs_std"])})
    with pytest.raises(ValueError, match="`weights` must be finite"):
        Policy.from_dict({**d, "weights": [[float("inf")] * len(d["obs_mean"])] * 3})
    with pytest.raises(ValueError, match="no pretrained policy 'walk'"):
        pretrained("walk")
    assert set(ballbot.gym.PRETRAINED) == {"balance", "balance_randomized"}
    assert pretrained("balance_randomized").env_kwargs == {"randomization": "recommended"}
