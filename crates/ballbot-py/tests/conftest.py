"""Shared fixtures: the presets the Rust tests use (MODEL.md section 6)."""

import pytest

import ballbot


@pytest.fixture
def wip() -> ballbot.Wip:
    return ballbot.Wip(ballbot.WipParams.preset("miapure_60kg"))


@pytest.fixture
def kin() -> ballbot.OmniKinematics:
    return ballbot.OmniKinematics.from_ballbot(ballbot.BallbotParams.preset("miapure_60kg"))
