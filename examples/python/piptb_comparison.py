"""Run the paper's PIPTB controller comparison (Sec. IV-C) and plot it.

The testbed accelerates from rest to 1 m/s in 2 s, holds, then tracks the optimal braking
trajectory to rest in 1.4 s, with stiction in its transmission and noisy sensors; each of the
three controllers (LQR, cascaded PI-PD, cascaded LQR-PI) runs the same seeded trials. The
paper reports the braking effort J_P = integral tau^2 over the braking phase: LQR-PI
8.2 +- 0.2 E5 and PI-PD 1.2 +- 0.3 E6 N^2 mm^2 s (PI-PD failed to stop in 1.4 s); LQR braked
but jittered. This prints the same table from the simulation and, if matplotlib is installed,
plots speed, tilt and torque of the first trial of each controller.

Usage: python examples/python/piptb_comparison.py [--quick] [--out DIR]
"""

import argparse
from pathlib import Path

import numpy as np

import ballbot

LABELS = {"lqr": "LQR", "pi_pd": "PI-PD", "lqr_pi": "LQR-PI"}


def print_table(result: ballbot.PiptbExperiment) -> None:
    print(f"{'controller':10s} {'J_P (N^2 mm^2 s)':>22s} {'paper':>18s} {'stopped':>8s} "
          f"{'jitter (N m)':>12s}")
    for key, c in result.controllers.items():
        paper = c["paper_j_p_n2mm2s"]
        paper_text = f"{paper[0]:.2g} +- {paper[1]:.1g}" if paper else "-"
        print(
            f"{LABELS[key]:10s} {c['j_p_n2mm2s']:>12.3g} +- {c['j_p_std'] * 1e6:<7.2g} "
            f"{paper_text:>18s} {str(c['stopped_all']):>8s} {c['torque_jitter_nm']:>12.3f}"
        )


def plot(result: ballbot.PiptbExperiment, out: Path) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: skipping the plot (pip install matplotlib)")
        return
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(8, 8))
    for key, c in result.controllers.items():
        s = c["trials"][0]["series"]
        axes[0].plot(s["time_secs"], s["speed_m_per_s"], label=LABELS[key])
        axes[1].plot(s["time_secs"], np.degrees(s["tilt_rad"]), label=LABELS[key])
        axes[2].plot(s["time_secs"], s["torque_nm"], label=LABELS[key], linewidth=0.8)
    first = next(iter(result.controllers.values()))["trials"][0]["series"]
    axes[0].plot(first["time_secs"], first["command_speed_m_per_s"], "k--", label="command")
    for ax in axes:
        ax.axvspan(result.brake_start_secs, result.brake_end_secs, color="0.9")
        ax.grid(True)
    axes[0].set_ylabel("ball speed (m/s)")
    axes[1].set_ylabel("tilt (deg)")
    axes[2].set_ylabel("torque (N m)")
    axes[2].set_xlabel("time (s)")
    axes[0].legend(loc="upper right")
    fig.suptitle("PIPTB controller comparison (braking phase shaded)")
    out.mkdir(parents=True, exist_ok=True)
    path = out / "piptb_comparison.png"
    fig.savefig(path, dpi=120)
    print(f"plot written to {path}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one trial, shorter hold")
    parser.add_argument("--out", type=Path, default=Path("out"), help="folder for plot and logs")
    args = parser.parse_args()
    result = ballbot.piptb_experiment(quick=args.quick, log_dir=args.out / "logs")
    print_table(result)
    print(f"MCAP logs of every trial in {args.out / 'logs'}")
    plot(result, args.out)


if __name__ == "__main__":
    main()
