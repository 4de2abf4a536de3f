"""The documents' fixed inputs (freefloat.documents): the chapter-4 task placed from them gives
the joint angles the dissertation prints in Table 4."""

from __future__ import annotations

import numpy as np

from freefloat.documents import DIRECTION, FIGS_38_40_OFFSET_DEG, TABLE_4_OFFSET_DEG, TASK_DEG, start_angles
from freefloat.lab.reproduce.printed import TABLE_4


def printed(which: int) -> np.ndarray:
    """Table 4's start (0) or end (1) angles of arms 1-4 in order (16,), deg."""
    return np.concatenate([TABLE_4[arm][which] for arm in (1, 2, 3, 4)])


def test_table_4_start_and_end_are_the_printed_angles():
    """The start at Table 4's offset, and that start moved by the task along each joint's direction,
    are Table 4's printed start and end angles."""
    start = np.degrees(start_angles(TABLE_4_OFFSET_DEG))
    np.testing.assert_allclose(start, printed(0), atol=1e-12)
    np.testing.assert_allclose(start + TASK_DEG * np.array(DIRECTION), printed(1), atol=1e-12)


def test_a_zero_offset_is_the_stretched_posture_and_offsets_move_along_the_direction():
    """Offset 0 is the stretched posture (arms 2 and 4 at 90 deg); each offset of figs 38-40 moves
    every joint by that many degrees along its direction."""
    stretched = start_angles(0.0)
    np.testing.assert_array_equal(np.flatnonzero(stretched), [4, 12])
    np.testing.assert_allclose(stretched[[4, 12]], np.pi / 2, rtol=0, atol=1e-15)
    for offset in FIGS_38_40_OFFSET_DEG.values():
        np.testing.assert_allclose(np.degrees(start_angles(offset) - stretched), offset * np.array(DIRECTION),
                                   atol=1e-12)
