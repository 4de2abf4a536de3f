"""The on-disk cache of checked robot loads: a hit gives the robot a fresh load gives, with the
same warnings; any change of the file's content, the options or the versions misses; a damaged
entry or an unusable folder is never an error nor a different model."""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import freefloat
from freefloat import RobotModelError
from freefloat.errors import FreefloatNote, FreefloatWarning
from freefloat.paths import URDF_DIR
from freefloat.robot import load_cache, loading, urdf_checks
from freefloat.robot.loading import load_robot

from .conftest import random_urdf

#: A base and two links: link l1's inertia breaks the triangle inequality, joint j2 has no <limit>
#: and l2's visual mesh is a file next to the URDF (warnings of three kinds).
URDF = """<robot name="c">
<link name="base"><inertial><origin xyz="0.1 0 0" rpy="0 0 0.3"/><mass value="10"/>
  <inertia ixx="1" iyy="2" izz="2.5" ixy="0" ixz="0" iyz="0"/></inertial></link>
<link name="l1"><inertial><mass value="2"/><inertia ixx="0.0123" iyy="0.01" izz="0.05" ixy="0" ixz="0" iyz="0"/>
  </inertial></link>
<link name="l2"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
  <inertia ixx="0.01" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial>
  <visual><geometry><mesh filename="l2.stl"/></geometry></visual></link>
<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0.5 0 0"/><axis xyz="0 0 1"/>
  <limit lower="-1" upper="1" effort="10" velocity="2"/></joint>
<joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.4 0 0" rpy="0.1 0 0"/>
  <axis xyz="0 1 0"/></joint>
</robot>"""


@pytest.fixture
def cache(tmp_path, monkeypatch) -> Path:
    """An empty cache folder of this test's own."""
    monkeypatch.setenv(load_cache.CACHE_DIR_VARIABLE, str(tmp_path / "cache"))
    return tmp_path / "cache" / "robots"


@pytest.fixture
def checks(monkeypatch) -> list[Path]:
    """The files the loader parsed and checked (a miss of the cache), one entry per check."""
    checked: list[Path] = []
    original = loading._check

    def counted(path, *args):
        checked.append(path)
        return original(path, *args)

    monkeypatch.setattr(loading, "_check", counted)
    return checked


def loaded(path: Path, **options) -> tuple[freefloat.Robot, list[tuple[type, str]]]:
    """The robot of ``path`` and the warnings its load gave (category, text), in order."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robot = load_robot(path, visuals=False, **options)
    return robot, [(w.category, str(w.message)) for w in caught]


def write(folder: Path, text: str, name: str = "c.urdf") -> Path:
    """``text`` written to ``folder/name`` (the folder created)."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_text(text)
    return folder / name


def assert_same_robot(cached: freefloat.Robot, fresh: freefloat.Robot) -> None:
    """Field by field, and the dynamics of both models on random states (Pinocchio's CRBA and
    ABA: an independent check of what the model's equality covers)."""
    a, b = cached.model, fresh.model
    assert a == b and a is not b
    assert [a.names[j] for j in range(a.njoints)] == [b.names[j] for j in range(b.njoints)]
    assert [(f.name, f.parentJoint, f.type) for f in a.frames] == [(f.name, f.parentJoint, f.type) for f in b.frames]
    for j in range(a.njoints):
        assert np.array_equal(a.jointPlacements[j].homogeneous, b.jointPlacements[j].homogeneous)
        assert a.inertias[j] == b.inertias[j]
    for limit in ("lowerPositionLimit", "upperPositionLimit", "velocityLimit", "effortLimit", "damping", "friction"):
        assert np.array_equal(getattr(a, limit), getattr(b, limit)), limit
    assert np.array_equal(a.gravity.vector, b.gravity.vector)
    for field in ("base_link", "base", "end_effectors", "urdf_path", "warnings", "notes", "missing_meshes"):
        assert getattr(cached, field) == getattr(fresh, field), field
    assert np.array_equal(cached.base_com, fresh.base_com)
    assert np.array_equal(cached.base_com_rotation, fresh.base_com_rotation)
    assert cached.link_coms.keys() == fresh.link_coms.keys()
    assert all(np.array_equal(cached.link_coms[k], fresh.link_coms[k]) for k in fresh.link_coms)
    assert [(arm.end_effector, arm.joints, arm.v_indices.tolist()) for arm in cached.arms] == \
           [(arm.end_effector, arm.joints, arm.v_indices.tolist()) for arm in fresh.arms]
    rng = np.random.default_rng(3)
    da, db = a.createData(), b.createData()
    for _ in range(5):
        q = pin.randomConfiguration(b, -np.ones(b.nq), np.ones(b.nq))
        v, tau = rng.normal(size=b.nv), rng.normal(size=b.nv)
        M = pin.crba(b, db, q)
        assert np.abs(pin.crba(a, da, q) - M).max() <= 1e-14 * np.abs(M).max()
        ddq = pin.aba(b, db, q, v, tau)
        assert np.abs(pin.aba(a, da, q, v, tau) - ddq).max() <= 1e-14 * max(1.0, np.abs(ddq).max())


@pytest.mark.parametrize("case", ["warned", "random", "four_arm_planar", "dual_arm_satellite"])
def test_a_cached_load_is_the_fresh_load(tmp_path, cache, checks, case):
    """The second load of a file comes from the cache (no parse, no checks) and equals a load that
    ignores the cache, on our warned file, a random tree and two built-in robots."""
    if case in ("warned", "random"):
        path = write(tmp_path / "robot", URDF if case == "warned" else random_urdf(np.random.default_rng(7), 12, 0.2))
    else:
        path = URDF_DIR / f"{case}.urdf"
    first, _ = loaded(path)
    cached, _ = loaded(path)
    assert len(checks) == 1 and len(list(cache.glob("*.json"))) == 1
    fresh, _ = loaded(path, cache=False)
    assert len(checks) == 2
    assert_same_robot(cached, fresh)
    assert_same_robot(first, fresh)


def test_a_hit_gives_the_same_warnings_and_notes_in_the_same_order(tmp_path, cache, checks):
    """Warnings (a broken triangle inequality, a missing limit, a missing mesh) and notes (a
    built-in robot's inertias) are given again on a hit, with their categories, in order."""
    path = write(tmp_path / "robot", URDF)
    _, missed = loaded(path)
    _, hit = loaded(path)
    assert len(checks) == 1
    assert hit == missed and len(missed) == 3 and all(category is FreefloatWarning for category, _ in missed)
    assert any("I1 + I2 >= I3" in text for _, text in missed) and any("no <limit>" in text for _, text in missed)
    _, missed = loaded(URDF_DIR / "four_arm_planar.urdf")
    _, hit = loaded(URDF_DIR / "four_arm_planar.urdf")
    assert hit == missed and [category for category, _ in hit] == [FreefloatNote]


def test_meshes_are_looked_for_at_every_load(tmp_path, cache, checks):
    """The mesh files are other files than the URDF: a mesh that appears after the entry was
    written is found on the hit (its note gone, the visual geometry built with it)."""
    path = write(tmp_path / "robot", URDF)
    first, missed = loaded(path)
    assert first.missing_meshes == (("l2", "l2.stl"),) and any("mesh not found" in text for _, text in missed)
    (tmp_path / "robot" / "l2.stl").write_text("solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                                               "vertex 0 1 0\nendloop\nendfacet\nendsolid s\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        second = load_robot(path)
    assert len(checks) == 1
    assert second.missing_meshes == () and not any("mesh not found" in str(w.message) for w in caught)
    assert second.visual_model is not None and second.visual_model.ngeoms == 1


def test_one_changed_byte_of_an_inertia_misses(tmp_path, cache, checks):
    """Editing one digit of an inertia loads the file again, and the model carries the new value."""
    path = write(tmp_path / "robot", URDF)
    loaded(path)
    path.write_text(URDF.replace('ixx="0.0123"', 'ixx="0.0124"'))
    robot, _ = loaded(path)
    assert len(checks) == 2 and len(list(cache.glob("*.json"))) == 2
    l1 = robot.model.getJointId("j1")
    assert robot.model.inertias[l1].inertia[0, 0] == pytest.approx(0.0124, rel=1e-15)


def test_the_same_content_elsewhere_hits_and_is_loaded_from_there(tmp_path, cache, checks):
    """A copy of the file in another folder hits the entry (the key is the content, not the
    path): the robot and the missing mesh's note name the copy's folder; a copy under another name
    misses (the warnings name the file)."""
    first, missed = loaded(write(tmp_path / "one", URDF))
    copy, hit = loaded(write(tmp_path / "two", URDF))
    assert len(checks) == 1 and copy.urdf_path == tmp_path / "two" / "c.urdf" and hit[:2] == missed[:2]
    assert hit[2] == (FreefloatWarning, missed[2][1].replace(str(tmp_path / "one"), str(tmp_path / "two")))
    renamed, warned = loaded(write(tmp_path / "two", URDF, "renamed.urdf"))
    assert len(checks) == 2 and all(text.startswith("renamed.urdf: ") for _, text in warned)


@pytest.mark.parametrize("option", [dict(base="planar"), dict(end_effectors=["l1"]), dict(inertias="balanced")])
def test_every_option_that_changes_the_robot_misses(tmp_path, cache, checks, option):
    """The base, the end-effectors and the inertias asked for are part of the key."""
    path = write(tmp_path / "robot", URDF)
    loaded(path)
    robot, _ = loaded(path, **option)
    assert len(checks) == 2
    fresh, _ = loaded(path, cache=False, **option)
    assert_same_robot(robot, fresh)


def test_gravity_is_set_on_a_hit(tmp_path, cache, checks):
    """Gravity is not part of the key: a hit takes the gravity asked for."""
    path = write(tmp_path / "robot", URDF)
    loaded(path)
    robot, _ = loaded(path, gravity=(0.0, 0.0, -9.81))
    assert len(checks) == 1 and robot.model.gravity.linear.tolist() == [0.0, 0.0, -9.81]


@pytest.mark.parametrize("version", ["freefloat", "pinocchio", "loader"])
def test_another_version_misses(tmp_path, cache, checks, monkeypatch, version):
    """An entry written by another freefloat, Pinocchio or loader source is not read."""
    path = write(tmp_path / "robot", URDF)
    loaded(path)
    if version == "freefloat":
        monkeypatch.setattr(load_cache, "_freefloat_version", lambda: freefloat.__version__ + ".post1")
    elif version == "pinocchio":
        monkeypatch.setattr(pin, "__version__", pin.__version__ + ".post1")
    else:
        monkeypatch.setattr(load_cache, "_loader_digest", lambda: "0" * 64)
    loaded(path)
    assert len(checks) == 2 and len(list(cache.glob("*.json"))) == 2


@pytest.mark.parametrize("damage", ["flip", "truncate", "empty", "garbage", "forged"])
def test_a_damaged_entry_is_loaded_again_and_rewritten(tmp_path, cache, checks, damage):
    """An entry changed after freefloat wrote it (one digit of a number in the model, cut short,
    empty, not ours, or a whole entry of other inputs) is ignored: the file is checked again, the
    robot equals a fresh load, and the entry is written again."""
    path = write(tmp_path / "robot", URDF)
    loaded(path)
    (entry,) = cache.glob("*.json")
    good = entry.read_bytes()
    at = good.index(b"e-0", good.index(b'"model"')) - 1  # the last digit of a number's mantissa in the model
    damaged = {
        "flip": good[:at] + str((int(good[at:at + 1]) + 1) % 10).encode() + good[at + 1:],
        "truncate": good[:len(good) // 3],
        "empty": b"",
        "garbage": b"\x80\x81 not json\n{",
    }
    if damage == "forged":  # a whole entry for another file under this file's name
        other = write(tmp_path / "other", URDF.replace('mass value="2"', 'mass value="3"'))
        loaded(other)
        damaged["forged"] = next(e for e in cache.glob("*.json") if e != entry).read_bytes()
    entry.write_bytes(damaged[damage])
    robot, _ = loaded(path)
    assert checks.count(path) == 2
    assert_same_robot(robot, loaded(path, cache=False)[0])
    assert entry.read_bytes() == good


def test_an_unusable_folder_means_no_cache(tmp_path, checks, monkeypatch):
    """A cache folder that cannot be made (a file is in the way) is no error: the robot loads."""
    (tmp_path / "in_the_way").write_text("a user's file")
    monkeypatch.setenv(load_cache.CACHE_DIR_VARIABLE, str(tmp_path / "in_the_way"))
    path = write(tmp_path / "robot", URDF)
    first, _ = loaded(path)
    second, _ = loaded(path)
    assert len(checks) == 2 and (tmp_path / "in_the_way").read_text() == "a user's file"
    assert_same_robot(second, first)


@pytest.mark.parametrize("off", ["variable", "option"])
def test_the_cache_can_be_turned_off(tmp_path, checks, monkeypatch, off):
    """``FREEFLOAT_CACHE_DIR=""`` or ``cache=False``: every load checks the file, nothing is written."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    if off == "variable":
        monkeypatch.setenv(load_cache.CACHE_DIR_VARIABLE, "")
    else:
        monkeypatch.setenv(load_cache.CACHE_DIR_VARIABLE, str(tmp_path / "cache"))
    path = write(tmp_path / "robot", URDF)
    for _ in range(2):
        loaded(path, **({} if off == "variable" else {"cache": False}))
    assert len(checks) == 2 and sorted(p.name for p in tmp_path.iterdir()) == ["robot"]


def test_the_cache_folder_follows_the_variables(tmp_path, monkeypatch):
    """``FREEFLOAT_CACHE_DIR``, else an absolute ``XDG_CACHE_HOME``, else ``~/.cache``."""
    monkeypatch.setenv(load_cache.CACHE_DIR_VARIABLE, str(tmp_path / "mine"))
    assert load_cache.cache_folder() == tmp_path / "mine" / "robots"
    monkeypatch.delenv(load_cache.CACHE_DIR_VARIABLE)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert load_cache.cache_folder() == tmp_path / "xdg" / "freefloat" / "robots"
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    for xdg in ("", "relative/cache"):
        monkeypatch.setenv("XDG_CACHE_HOME", xdg)
        assert load_cache.cache_folder() == tmp_path / "home" / ".cache" / "freefloat" / "robots"


def test_the_memory_check_holds_on_a_hit(tmp_path, cache, checks, monkeypatch):
    """The memory a robot needs is checked against this machine at every load, a hit too."""
    path = write(tmp_path / "robot", URDF)
    loaded(path)
    monkeypatch.setattr(urdf_checks, "MEMORY_SHARE", 1e-9)
    with pytest.raises(RobotModelError, match="2 movable joints: a simulation would need about"):
        loaded(path)
    assert len(checks) == 1


def test_the_tests_never_use_the_users_cache():
    """The session's cache folder is a temporary one (tests/conftest.py), not ``~/.cache``."""
    from .conftest import CACHE_DIR

    assert load_cache.cache_folder() == Path(CACHE_DIR) / "robots"
    assert not Path(CACHE_DIR).is_relative_to(Path.home() / ".cache")


def test_the_least_recently_used_entries_beyond_the_limit_are_removed(tmp_path, cache, checks, monkeypatch):
    """Beyond MAX_ENTRIES the entry used longest ago goes (a hit counts as a use); files that are
    not entries stay."""
    monkeypatch.setattr(load_cache, "MAX_ENTRIES", 2)
    entries = {}
    for name in ("a", "b"):
        before = set(cache.glob("*.json"))
        loaded(write(tmp_path / name, URDF.replace('mass value="2"', f'mass value="{len(entries) + 3}"')))
        (entries[name],) = set(cache.glob("*.json")) - before
    for age, name in enumerate(("a", "b")):
        os.utime(entries[name], ns=(10**18 + age, 10**18 + age))
    keep = [cache / "notes.txt", cache / ("0" * 64 + ".bin")]
    for path in keep:
        path.write_text("a user's file")
    loaded(tmp_path / "a" / "c.urdf")  # a hit: "a" is now the most recently used
    loaded(write(tmp_path / "c", URDF))
    assert len(checks) == 3 and entries["a"].exists() and not entries["b"].exists()
    assert len(list(cache.glob("*.json"))) == 2 and all(path.read_text() == "a user's file" for path in keep)
