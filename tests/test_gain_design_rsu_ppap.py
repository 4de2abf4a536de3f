"""The 2RSU+PPaP's dynamics are affine in its uncertain masses: H, g_M and v_M rebuilt from the
gain design's coefficients at a mass set equal Pinocchio's CRBA, gravity and Coriolis terms of the
URDF regenerated from the data file with those masses, projected by the constraint complement C."""

from __future__ import annotations

import copy

import numpy as np
import pinocchio as pin
import pytest

from freefloat.errors import FreefloatError
from freefloat.parallel.rsu_ppap import load_data, load_rsu_ppap, rsu_ppap_urdf
from freefloat.parallel.rsu_ppap_masses import RsuPpapModel, plant_masses, with_masses
from freefloat.robot.builders import urdf_xml

DATA = load_data()
#: An off-nominal mass set: every uncertain mass at a different point of its interval.
THETA = np.array([mass * (1.0 + f) for mass, f in
                  zip((1.5, 0.5, 0.25, 0.02, 0.8, 0.15, 0.3), (0.12, -0.07, 0.15, -0.15, 0.05, 0.1, -0.11))])


@pytest.fixture(scope="module")
def loaded():
    return load_rsu_ppap()


@pytest.fixture(scope="module")
def model(loaded):
    return RsuPpapModel(loaded.mechanism, DATA)


def pinocchio_platform_dynamics(loaded, masses: dict[str, float], q: np.ndarray, qd_sharp: np.ndarray):
    """``(H, v_M, g_M)`` from Pinocchio on the URDF generated with ``masses``: ``S C`` maps the
    platform rates to the tree's joint rates (S: Orsino's coordinates -> the tree's, bar 2 with
    bar 1), ``H = (S C)^T M (S C)``, ``g_M = (S C)^T g(q)``, ``v_M = (S C)^T (M S c + C(q, v) v)``
    with ``c = [0; A°^+ b]`` Orsino's acceleration bias (kinematics only)."""
    data = copy.deepcopy(DATA)
    for key, value in masses.items():
        section, name = key.split(".")
        data[section][name] = value
    model = pin.buildModelFromXML(urdf_xml(rsu_ppap_urdf(data)))
    model.gravity.linear = loaded.model.gravity.linear.copy()
    pdata = model.createData()
    mech = loaded.mechanism.reference()
    qd = mech.velocity_map(q) @ qd_sharp
    A, b, C, *_ = mech.terms(q, qd)
    c = np.concatenate((np.zeros(mech.p), mech.passive_solve(A, b[:, None])[:, 0]))
    to_tree = {model.getJointId(loaded.model.names[j]): i for j, i in loaded.joint_coordinates.items()}

    def tree(x):
        out = np.zeros(model.nv)
        for j, i in to_tree.items():
            out[model.idx_vs[j]] = x[i]
        return out

    SC = np.column_stack([tree(col) for col in C.T])
    qt, vt = tree(q), tree(qd)
    M = pin.crba(model, pdata, qt)
    M = np.triu(M) + np.triu(M, 1).T
    g = pin.computeGeneralizedGravity(model, pdata, qt)
    coriolis = pin.nonLinearEffects(model, pdata, qt, vt) - g
    return SC.T @ M @ SC, SC.T @ (M @ tree(c) + coriolis), SC.T @ g


@pytest.mark.parametrize("offset", [(0.0, 0.0, 0.0), (0.03, -0.02, -0.03)])
def test_coefficients_rebuild_pinocchios_dynamics_at_other_masses(loaded, model, offset):
    """Sum_k pi_k(theta) H_k, g_k and sum_ij delta_ij qd_i qd_j equal Pinocchio's projected
    H, g_M and v_M of the URDF regenerated with the masses theta (inertias from the masses and
    shapes by the generator: the scaling assumption checked too)."""
    point = np.array(DATA["home"]) + np.array(offset)
    q = model.assemble(point)
    H_c, g_c, quad_c = model.coefficients(q)
    pi = model.linear_parameters(THETA)
    qd = np.array([0.2, -0.3, 0.15])
    H, v, g = pinocchio_platform_dynamics(loaded, dict(zip(model.names, THETA)), q, qd)
    np.testing.assert_allclose(np.tensordot(pi, H_c, 1), H, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(pi @ g_c, g, rtol=1e-10, atol=1e-10)
    v_M = sum((pi @ c) * qd[i] * qd[j] for (i, j), c in quad_c.items())
    np.testing.assert_allclose(v_M, v, rtol=1e-9, atol=1e-11)


def test_with_masses_scales_only_the_named_bodies(loaded):
    """The 15 % plant's crank links weigh 1.15 x 0.5 kg, the knuckles 1.15 x 0.02 kg, the slider
    0.85 x 0.8 kg, the bars 0.85 x 2 x 0.15 kg; a mass left out keeps the data file's."""
    plant = with_masses(loaded.mechanism, DATA, plant_masses(DATA, "true_15"))
    np.testing.assert_allclose(plant.chains[0].mass, 1.15 * np.array([0.5, 0.02, 0.02, 0.25, 0.02, 0.02]))
    np.testing.assert_allclose(plant.chains[2].mass, [0.85 * 0.8, 0.85 * 0.3, 0.85 * 0.3, 1.15 * 1.5])
    only = with_masses(loaded.mechanism, DATA, {"rsu.rod_mass": 0.5})
    np.testing.assert_allclose(only.chains[1].mass, [0.5, 0.02, 0.02, 0.5, 0.02, 0.02])


def test_with_masses_refuses_a_urdf_of_other_masses(loaded):
    """Data whose crank mass is not the URDF's: the joint and the key are named."""
    data = copy.deepcopy(DATA)
    data["rsu"]["crank_mass"] = 0.6
    with pytest.raises(FreefloatError, match="rsu1_crank.*rsu.crank_mass.*regenerate"):
        with_masses(loaded.mechanism, data, {})


@pytest.mark.parametrize("edit, match", [
    (lambda text: text.split("[uncertainty]")[0], "missing table 'uncertainty'"),
    (lambda text: text.replace('"rsu.rod_mass" = 0.0375', '"rsu.rod_length" = 0.01'), "rsu.rod_length"),
    (lambda text: text.replace('"platform.mass" = 0.225', '"platform.mass" = 1.5'), r"in \(0, 1.5\) kg"),
])
def test_data_file_uncertainty_table_is_checked(tmp_path, edit, match):
    """A missing [uncertainty], a key that is no mass, a half-width as large as the mass."""
    from freefloat.parallel.rsu_ppap import DATA as PATH

    (tmp_path / "d.toml").write_text(edit(PATH.read_text()))
    with pytest.raises(FreefloatError, match=match):
        load_data(tmp_path / "d.toml")


def test_tree_inertias_are_the_regenerated_urdfs(loaded):
    """The spanning tree's bodies scaled for the 50 % plant (what a moving-base scene simulates)
    equal those of the URDF generated with the plant's masses (to the URDF's printed digits)."""
    from freefloat.parallel.rsu_ppap_masses import tree_inertias

    masses = plant_masses(DATA, "true_50")
    model = pin.Model(loaded.model)
    tree_inertias(DATA, masses, model)
    data = copy.deepcopy(DATA)
    for key, value in masses.items():
        section, name = key.split(".")
        data[section][name] = value
    regenerated = pin.buildModelFromXML(urdf_xml(rsu_ppap_urdf(data)))
    for j in range(1, model.njoints):
        ours, ref = model.inertias[j], regenerated.inertias[regenerated.getJointId(model.names[j])]
        np.testing.assert_allclose(ours.toDynamicParameters(), ref.toDynamicParameters(), rtol=1e-9, atol=1e-15)
