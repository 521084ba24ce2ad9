"""MCAP logs: ``McapLog`` reads what ``World.run(log_path=...)``, ``Scenario.run`` and the
``ballbot`` CLI write."""

from ballbot._core import McapLog

__all__ = ["McapLog"]
