"""The failing ramp acceleration per world mechanism (docs/mechanisms.md).

Each realistic mechanism of the 3D world (roller gaps, roller losses along the axle, the rubber
coating, the ODrive motor driver) is switched on alone in the ideal world, then all together
(the default world), and the largest surviving ramp acceleration is searched at each heading.

    python examples/python/mechanism_failing_accel.py --headings 0 90
"""

import argparse
import time
from typing import Any

import ballbot


def variants() -> dict[str, ballbot.WorldParams]:
    """The ideal world, each mechanism alone, and the default world."""
    full: dict[str, Any] = ballbot.WorldParams.preset("miapure_60kg").to_dict()
    ideal: dict[str, Any] = ballbot.WorldParams.preset("ideal_miapure_60kg").to_dict()
    contact = ideal["contact"]
    worlds = {
        "ideal": ideal,
        "roller_gaps": {**ideal, "contact": {**contact, "rollers": full["contact"]["rollers"]}},
        "axle_losses": {
            **ideal,
            "contact": {**contact, "axle_loss": full["contact"]["axle_loss"]},
        },
        "rubber_coating": {
            **ideal,
            "contact": {
                **full["contact"],
                "rollers": contact["rollers"],
                "axle_loss": contact["axle_loss"],
            },
        },
        "motor_driver": {**ideal, "driver": full["driver"]},
        "drivetrain": {**ideal, "transmission": full["transmission"]},
        "sensing": {**ideal, "sensors": ballbot.SensorParams.preset("miapure").to_dict()},
        "all": full,
    }
    return {name: ballbot.WorldParams.from_dict(d) for name, d in worlds.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--headings", type=float, nargs="+", default=[0.0, 90.0])
    parser.add_argument("--bracket", type=float, nargs=2, default=[1.0, 2.2])
    parser.add_argument("--resolution", type=float, default=0.05)
    args = parser.parse_args()
    start = time.perf_counter()
    print(f"{'world':>16} | " + " | ".join(f"{h:>5.0f} deg: surviving / failing" for h in args.headings))
    for name, params in variants().items():
        cells = []
        for heading in args.headings:
            found = ballbot.failing_acceleration(
                params,
                heading_deg=heading,
                accel_bracket_m_per_s2=tuple(args.bracket),
                accel_resolution_m_per_s2=args.resolution,
            )
            failing = found.failing
            what = failing.failure.kind.value if failing and failing.failure else "-"
            cells.append(
                f"{found.largest_surviving_m_per_s2} / {found.smallest_failing_m_per_s2} ({what})"
            )
        print(f"{name:>16} | " + " | ".join(f"{c:>30}" for c in cells), flush=True)
    print(f"{len(args.headings) * 6} searches in {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()
