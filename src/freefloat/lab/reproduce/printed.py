"""What the documents print, as they print it: the numbers the studies and the report of
``freefloat reproduce`` set beside freefloat's (units as printed; a value the documents give as
text stays text). The inputs the product reads too (the task's start) are in
:mod:`freefloat.documents`.
"""

from __future__ import annotations

# ------------------------------------------------------------------ the dissertation
#: Table 1 (nested RMS joint tracking error, eq 140, rad; arms 1-4 then overall), plant FM-NIC-A,
#: by the controller's model: FM-NIC-A (``nidc``) and FM-ST-A (``standard``).
TABLE_1 = {"nidc": [4.91e-7, 4.91e-7, 4.91e-7, 4.91e-7, 4.91e-7],
           "standard": [1.18e-4, 1.18e-4, 1.13e-4, 1.13e-4, 1.16e-4]}
#: Sec 5.1: FM-ST-A's overall Table 1 error over FM-NIC-A's, "236 times worse".
TABLE_1_RATIO = 236.0
#: Table 2: RMS of the task-space end-effector pose error per arm 1-4 (x, y in m, z-rotation in deg).
TABLE_2 = {"x": [1.09e-5, 2.84e-5, 2.24e-6, 2.84e-5], "y": [2.84e-5, 1.09e-5, 2.84e-5, 2.24e-6],
           "z_deg": [5.3e-4] * 4, "overall": [3.1e-4] * 4}
#: Table 3: kinematic consistency (KJC) RMS per arm 1-4 (m/s, deg/s).
TABLE_3 = {"x": [3.85e-6, 4.34e-7, 4.16e-6, 4.34e-7], "y": [4.34e-7, 3.85e-6, 4.33e-7, 4.16e-6],
           "z_deg": [0.0] * 4, "overall": [2.23e-6, 2.23e-6, 2.41e-6, 2.41e-6]}
#: Table 4: per arm, joint angles (deg) at the start and the end of both runs of sec 5.2.
TABLE_4 = {1: ([0.5] * 4, [5.5] * 4), 2: ([89.5, -0.5, -0.5, -0.5], [84.5, -5.5, -5.5, -5.5]),
           3: ([-0.5] * 4, [-5.5] * 4), 4: ([90.5, 0.5, 0.5, 0.5], [95.5, 5.5, 5.5, 5.5])}
#: Table 5: per arm, the end-effector's (x, y in m, z-rotation in deg) at the start and the end.
TABLE_5 = {"arm1": ((7.75, 0.13, 2.0), (7.34, 1.2, 22.0)), "arm2": ((0.13, 7.75, 88.0), (1.2, 7.34, 68.0)),
           "arm3": ((-7.75, 0.13, -2.0), (-7.78, 1.2, -22.0)), "arm4": ((0.13, -7.75, 92.0), (1.2, -7.78, 112.0))}
#: Fig 6 (sec 4.2.1): the end-effectors of arms 1-4 at the start, x, y (m).
FIG_6_END_EFFECTORS = ("7.75, 0", "0, 7.75", "-7.75, 0", "0, -7.75")
#: Sec 4.2.2 (figs 14, 19): the system CoM's drift (m), put down to the sequential base/joint update.
COM_DRIFT_M = 1e-7
#: Sec 4.2.1: arm 4's pivot, a typo.
ARM_4_PIVOT = "[-1, 75, 0, 0]"
#: Eq 140: n_T, the samples of a 5 s run at 1 ms.
EQ_140_SAMPLES = 500
#: Sec 5.3: the detumbling scenes' sampling period.
SEC_5_3_SAMPLING = "0.001 ms"
#: Sec 4.3 (eq 137), the gains of every run of chapters 4-5, figs 42-44's baseline included:
#: Kp = 10 I (1/s^2), Kd = 100 I (1/s).
COMPUTED_TORQUE_GAINS = {"kp": 10.0, "kd": 100.0}
#: Sec 5.3 (fig 45): the change of arm 1's end-effector angle during the capture (mdeg).
CAPTURE_ANGLE_CHANGE_MDEG = 0.02

# ------------------------------------------------------------------ the thesis, sec 5.6 (the 5R)
#: The 5R's start and the circle of eq 189's: the end-effector at rest at (x, y) (m).
START = (0.07, 0.17)
#: Eq 189: the reference circle's centre (m) and radius (m), and its angular rate (rad/s).
CIRCLE_CENTRE, CIRCLE_RADIUS, CIRCLE_RATE = (0.0, 0.17), 0.07, 28.57
#: Table 2 and fig 7: the RR chain's link lengths l1, l2 (m).
LINKS = "0.12, 0.15"
#: Eq 187: the worst-case sliding-mode gains (x, y): n, the entries of N (xdot^2, xdot ydot,
#: ydot^2) and T (rows).
EQ_187 = {"n": [75.3, 108.0], "xdot2": [37.0, 54.1], "xdot_ydot": [22.7, 35.5], "ydot2": [17.5, 28.5],
          "T": [[1.25, 0.92], [1.68, 1.65]]}
#: Sec 5.6: lambda of the sliding surface and of computed torque (1/s).
LAMBDA = 40.0
#: Sec 5.6: the time s_y takes to reach |s| < 0.02 (s).
REACHING_TIME_S = 0.008
#: Fig 9: the saturation tanh(GAIN s) that replaces sign(s), and its value at s = 0.023.
SATURATION_GAIN, SATURATION_AT_0_023 = 100.0, 0.98
#: Figs 22-23: the computed-torque run's peak errors x, y (mm).
COMPUTED_TORQUE_PEAKS_MM = (12.0, 27.0)
#: Sec 5.6: the sliding surface at the start, s(0).
S_0 = "[0, -2]"
