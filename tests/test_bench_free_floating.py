"""The free-floating bench scenes: the detumbling scene's MuJoCo runs apply freefloat's controller
and impulses, its planar-base variant is the same motion, and the tumbling sweep's hand-built
models show their model errors."""

from __future__ import annotations

import warnings

import pytest

from freefloat.lab.bench.race.scene import Method
from freefloat.lab.bench.race.sweep import measure
from freefloat.lab.bench.scenes.free_floating import free_floating_scene


@pytest.fixture(scope="module")
def detumbling():
    """The detumbling scene over 50 ms (the impulses act from 5 to 15 ms), quick sweep."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return free_floating_scene("detumbling", quick=True)


@pytest.fixture(scope="module")
def detumbling_ref(detumbling):
    """Its dopri5 reference."""
    return detumbling.reference()


@pytest.mark.parametrize(("freefloat", "mujoco"), [("euler", "Euler"), ("rkmk4", "RK4")])
def test_mujoco_detumbles_like_freefloat(detumbling, detumbling_ref, freefloat, mujoco):
    """MuJoCo stepped by freefloat's detumbling controller, with the impulses as xfrc_applied, ends
    with the error of freefloat's same-order method at the same step (1e-6 relative for Euler, 2 %
    for the two RK4s): same law, same impulses."""
    ff = measure(detumbling, Method("freefloat", freefloat, 5e-4, "compiled"), detumbling_ref, 1).state_error
    mj = measure(detumbling, Method("mujoco", mujoco, 5e-4), detumbling_ref, 1).state_error
    assert 1e-12 < ff
    assert mj == pytest.approx(ff, rel=1e-6 if freefloat == "euler" else 0.02)


@pytest.mark.parametrize("name", ["detumbling", "controlled"])
def test_planar_base_ends_where_the_free_base_does(name):
    """The planar-base variant (3 base DOF instead of 6) ends at the free base's state, mapped, to
    round-off: the scene is planar, the smaller model loses nothing."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = free_floating_scene(name, quick=True)
    ref = scene.reference()
    free = measure(scene, Method("freefloat", "rkmk4", 5e-4, "compiled"), ref, 1).state_error
    planar = measure(scene, Method("freefloat", "rkmk4", 5e-4, "compiled", "planar base"), ref, 1)
    assert 1e-12 < planar.state_error == pytest.approx(free, rel=1e-5)


def test_detumbling_sweep_has_every_side(detumbling):
    """The sweep holds the compiled loop, the Python loop, the planar base and MuJoCo."""
    labels = {m.label for m in detumbling.methods()}
    assert {"freefloat rkmk4 compiled", "freefloat rkmk4", "freefloat rkmk4 planar base compiled",
            "mujoco RK4"} <= labels


@pytest.fixture(scope="module")
def tumbling():
    """The dual-arm satellite tumbling for 0.1 s, quick sweep."""
    return free_floating_scene("dual_arm", quick=True)


def test_corrected_hand_built_model_is_exact(tumbling):
    """RKMK4 on FM-ST-A corrected (the GJM model) ends where RKMK4 on Pinocchio's ABA does."""
    ref = tumbling.reference()
    exact = measure(tumbling, Method("freefloat", "rkmk4", 1e-2), ref, 1).state_error
    corrected = measure(tumbling, Method("freefloat", "rkmk4", 1e-2, model="standard_corrected"), ref, 1).state_error
    assert corrected == pytest.approx(exact, rel=1e-6)


def test_printed_model_error_does_not_fall_with_the_step(tumbling):
    """FM-ST-A as printed (c0 = 0) is wrong with non-zero momentum: halving the step leaves its
    error where it was (within 10 %), far above the exact plant's."""
    ref = tumbling.reference()
    coarse, fine = (measure(tumbling, Method("freefloat", "rkmk4", h, model="standard"), ref, 1).state_error
                    for h in (1e-2, 5e-3))
    exact = measure(tumbling, Method("freefloat", "rkmk4", 5e-3), ref, 1).state_error
    assert fine == pytest.approx(coarse, rel=0.1) and fine > 1e3 * exact
