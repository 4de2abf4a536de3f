"""The documents' fixed inputs that more than one part of freefloat reads: the chapter-4 task of
the dissertation's four-arm robot (its start posture, the direction each joint moves, the start
offsets of Table 4 and figs 38-40), read by the atlas (figs 38-40, the reference posture) and by
the studies of ``freefloat reproduce``.

Numbers as the dissertation gives them (deg, s), in tuples, and the one function that places a
start from them. Base layer: imports nothing of freefloat.
"""

from __future__ import annotations

import numpy as np

#: Sec 4.2.1: the stretched posture, joint angles in deg (16,), arms 1-4 in order with four
#: joints each; arms 2 and 4 turn their first joint by 90 deg (arms along +x, +y, -x, -y).
STRETCHED_DEG = (0.0,) * 4 + (90.0, 0.0, 0.0, 0.0) + (0.0,) * 4 + (90.0, 0.0, 0.0, 0.0)
#: Sec 4.2.2: the direction each joint moves in the task (16,): +1 on arms 1 and 4, -1 on arms
#: 2 and 3.
DIRECTION = (1.0,) * 4 + (-1.0,) * 8 + (1.0,) * 4
#: Sec 4.2.2: every joint moves this far along its direction (deg) ...
TASK_DEG = 5.0
#: ... in this time (s), along a quintic.
TASK_S = 5.0
#: Table 4: the runs of sec 5.2 start every joint this far (deg) along its direction.
TABLE_4_OFFSET_DEG = 0.5
#: Figs 38-40: the start offset (deg) of each figure's condition number of the E-GJM.
FIGS_38_40_OFFSET_DEG = {38: 0.1, 39: 1.0, 40: 0.0}


def start_angles(offset_deg: float) -> np.ndarray:
    """The task's start (16,) rad: the stretched posture with every joint ``offset_deg`` along
    its direction (Table 4: 0.5 deg)."""
    return np.radians(offset_deg) * np.array(DIRECTION) + np.radians(STRETCHED_DEG)
