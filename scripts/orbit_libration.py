"""In orbit (issue 39 item 1), measured: the pitch libration of a rigid satellite released 5 deg
off its gravity-gradient equilibrium at 400 km (``libration_period``, s, from the motion, against
the closed form and the finite-amplitude pendulum), a free body's drift against the
Clohessy-Wiltshire closed form over one orbit at three offsets, and the Earth-centred energy and
angular momentum of the dual-arm satellite tumbling through one orbit of the full two-body field.
Prints one table, writes runs/orbit-<time>/orbit.json and the figure docs/img/orbit.png
(docs/orbit.md quotes both).

    python3 scripts/orbit_libration.py
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np

from freefloat import load_robot
from freefloat.paths import URDF_DIR
from freefloat.space.orbit import CircularOrbit, OrbitField, clohessy_wiltshire, free_flyer_state, root_in_lvlh
from freefloat.space.orbit.libration import measure_libration, rigid_satellite
from freefloat.space.orbit.propagation import propagate

ORBIT = CircularOrbit(altitude=400e3)
#: A free body's LVLH release per metre of offset: position (m) and velocity (m/s); it drifts
#: -6 pi (2 x0 + y0' / n) = -9.4 m along-track per orbit and metre of offset.
CW_POSITION, CW_VELOCITY = np.array([1.0, 0.5, -0.8]), ORBIT.mean_motion * np.array([0.3, -1.5, 0.6])


def clohessy_wiltshire_drift(offset: float) -> dict:
    """A 10 kg body released ``offset`` times the unit relative state, through one orbit of the full
    field (dopri5, rtol 1e-12): the largest distance from the CW closed form, m, its LVLH track."""
    model = rigid_satellite(10.0, (1.0, 2.0, 3.0))
    p0, v0 = offset * CW_POSITION, offset * CW_VELOCITY
    t = np.linspace(0.0, ORBIT.period, 401)
    Q, V = propagate(model, [OrbitField(model, ORBIT)], *free_flyer_state(ORBIT, 0.0, p0, v0), t, rtol=1e-12)
    track, (closed, _) = root_in_lvlh(ORBIT, t, Q, V).position, clohessy_wiltshire(ORBIT.mean_motion, p0, v0, t)
    return {"offset": offset, "error": float(np.linalg.norm(track - closed, axis=1).max()),
            "extent": float(np.linalg.norm(closed, axis=1).max()), "track": track, "closed": closed}


def balances(rtol: float) -> dict:
    """The dual-arm satellite 100 m off the reference, tumbling, arms free, through one orbit:
    relative drifts of the Earth-centred energy and angular momentum, and of the robot's own
    parts of them (over the reference point's), at dopri5 ``rtol``; wall time, s."""
    robot = load_robot(URDF_DIR / "dual_arm_satellite.urdf", visuals=False)
    model, field = robot.model, OrbitField(robot, ORBIT)
    q0 = robot.neutral()
    q0[:3], q0[7:] = [60.0, -70.0, 40.0], np.random.default_rng(2).uniform(-1.0, 1.0, model.nq - 7)
    v0 = np.r_[0.02, 0.05, -0.01, 0.002, -0.003, 0.004, np.full(model.nv - 6, 0.001)]
    t = np.linspace(0.0, ORBIT.period, 41)
    start = time.perf_counter()
    Q, V = propagate(robot, [field], q0, v0, t, rtol=rtol, atol=1e-12)
    wall = time.perf_counter() - start

    def drift(values: list) -> float:
        values = np.array(values).reshape(len(t), -1)
        return float(np.linalg.norm(values - values[0], axis=1).max() / np.linalg.norm(values, axis=1).max())

    states = list(zip(t, Q, V))
    return {"rtol": rtol, "wall_s": wall,
            "energy": drift([field.energy(*s) for s in states]),
            "angular_momentum": drift([field.angular_momentum(*s) for s in states]),
            "energy_over_reference": drift([field.energy_over_reference(*s) for s in states]),
            "momentum_over_reference": drift([field.momentum_over_reference(*s) for s in states])}


def figure(libration, drift: dict) -> None:
    """docs/img/orbit.png: the pitch libration over time; the free body's LVLH track and CW's."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4))
    left.plot(libration.t / 60.0, np.degrees(libration.pitch), lw=1.2)
    left.set(xlabel="time (min)", ylabel="pitch from LVLH (deg)",
             title=f"libration: {libration.period:.2f} s measured, {libration.closed_form:.2f} s closed form")
    right.plot(drift["closed"][:, 1], drift["closed"][:, 0], "k--", lw=2.5, label="Clohessy-Wiltshire")
    right.plot(drift["track"][:, 1], drift["track"][:, 0], lw=1.2, label="full two-body field")
    right.set(xlabel="along-track y (m)", ylabel="radial x (m)",
              title=f"free body over one orbit, {drift['offset']:g} m offset (LVLH)")
    right.legend()
    fig.tight_layout()
    fig.savefig(Path(__file__).resolve().parents[1] / "docs" / "img" / "orbit.png", dpi=110)


def main() -> None:
    out = Path("runs") / f"orbit-{time.strftime('%Y%m%d-%H%M%S')}"
    out.mkdir(parents=True)
    libration = measure_libration(amplitude=math.radians(5.0))
    drifts = [clohessy_wiltshire_drift(offset) for offset in (1.0, 10.0, 100.0)]
    balance = [balances(rtol) for rtol in (1e-10, 1e-12)]
    report = {"orbit": {"altitude_m": ORBIT.altitude, "mean_motion_rad_s": ORBIT.mean_motion, "period_s": ORBIT.period},
              "libration_period": libration.period, "libration_closed_form": libration.closed_form,
              "libration_pendulum": libration.pendulum,
              "clohessy_wiltshire": [{k: d[k] for k in ("offset", "error", "extent")} for d in drifts],
              "balances": balance}
    (out / "orbit.json").write_text(json.dumps(report, indent=1))
    print(f"orbit: {ORBIT.altitude / 1e3:g} km, n = {ORBIT.mean_motion:.9g} rad/s, period {ORBIT.period:.3f} s")
    print(f"libration_period {libration.period:.3f} s; closed form {libration.closed_form:.3f} s "
          f"({libration.period / libration.closed_form - 1:+.3%}); pendulum at 5 deg {libration.pendulum:.3f} s "
          f"({libration.period / libration.pendulum - 1:+.2e})")
    for d in drifts:
        print(f"CW, offset {d['offset']:6g} m: largest distance {d['error']:.3e} m over an extent of {d['extent']:.3g} m")
    for b in balance:
        print(f"dual-arm satellite, rtol {b['rtol']:g} ({b['wall_s']:.1f} s): energy {b['energy']:.1e}, angular momentum "
              f"{b['angular_momentum']:.1e}; over the reference: {b['energy_over_reference']:.1e}, "
              f"{b['momentum_over_reference']:.1e}")
    figure(libration, drifts[1])
    print(f"wrote {out / 'orbit.json'} and docs/img/orbit.png")


if __name__ == "__main__":
    main()
