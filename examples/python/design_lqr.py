"""Design the paper's LQR for MiaPURE carrying 60 kg, check it, and try it on the nonlinear model.

Prints the continuous and 400 Hz discrete gains on [theta, theta_dot, phi_dot] (MODEL.md:
k = [-234.8, -45.70, -3.162] for Q = diag(100, 10, 1), R = 0.1), the closed-loop poles, how
the gains move with the payload and the tilt weight, and the largest initial lean the
saturated controller recovers on the nonlinear WIP.

Usage: python examples/python/design_lqr.py
"""

import numpy as np

import ballbot

MAX_TORQUE_NM = 83.9  # MiaPURE's planar torque capacity about x (MODEL.md section 6)


def main() -> None:
    wip = ballbot.Wip(ballbot.WipParams.preset("miapure_60kg"))
    print(f"open-loop poles: {np.round(np.sort(wip.open_loop_poles().real), 2)} rad/s")

    lqr = ballbot.wip_lqr(wip, q=[100.0, 10.0, 1.0], r=0.1)
    print(f"continuous gains k = {np.round(lqr.reduced_gains(), 3)}")
    print(f"closed-loop poles  = {np.round(np.sort(lqr.closed_loop_eigenvalues().real), 2)}")
    disc = ballbot.wip_lqr_discrete(wip, dt_secs=1.0 / 400.0)
    z = disc.closed_loop_eigenvalues()
    print(f"400 Hz gains k     = {np.round(disc.reduced_gains(), 3)}, |z| max {np.abs(z).max():.4f}")

    print("\npayload and tilt weight:")
    for preset in ("miapure_unloaded", "miapure_60kg"):
        plane = ballbot.Wip(ballbot.WipParams.preset(preset))
        for q_tilt in (10.0, 100.0, 1000.0):
            k = ballbot.wip_lqr(plane, q=[q_tilt, 10.0, 1.0], r=0.1).reduced_gains()
            print(f"  {preset:17s} q_theta={q_tilt:6.0f}: k = {np.round(k, 2)}")

    # Largest recoverable lean: 200 initial leans in one batch on the nonlinear model.
    controller = ballbot.LqrController(lqr.controller_gains(MAX_TORQUE_NM))
    leans_deg = np.linspace(0.0, 40.0, 200)
    initial = np.zeros((leans_deg.size, 4))
    initial[:, 0] = np.radians(leans_deg)
    run = ballbot.closed_loop_rollout(wip, controller, initial, n_steps=4000)
    final = run.state[:, -1, :]
    recovered = (np.abs(final[:, 0]) < 1e-3) & (np.abs(final[:, 3]) < 1e-2)
    # Leans are sorted: the first failure bounds the recoverable range.
    first_failure = leans_deg[~recovered].min() if not recovered.all() else None
    timing = f"{run.compute_secs * 1e3:.0f} ms for {leans_deg.size} x 10 s in Rust"
    if first_failure is None:
        print(f"\nrecovers every lean up to {leans_deg[-1]:.0f} deg ({timing})")
    else:
        print(
            f"\nrecovers every lean below {first_failure:.1f} deg with |tau| <= "
            f"{MAX_TORQUE_NM} N m ({timing})"
        )


if __name__ == "__main__":
    main()
