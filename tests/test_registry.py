"""The one registry type (freefloat.registry.Registry) and the plug-ins that fill registries:
entry points of group freefloat.plugins and a user's own file or module (freefloat.registry.use)."""

from __future__ import annotations

import sys
import textwrap
import threading
import time
import types
from dataclasses import dataclass
from importlib import metadata

import pytest

from freefloat import registry
from freefloat.errors import InvalidArgument, PluginError, UnknownName
from freefloat.registry import GROUP, Registry, load_plugins, use


@dataclass(frozen=True)
class Toy:
    """A registry entry: a name and a value."""

    name: str
    gain: float = 1.0


@pytest.fixture
def toys(monkeypatch, tmp_path):
    """A fresh toy registry importable as ``toy_families.TOYS``, plug-ins not loaded yet, no entry
    point but those a test fakes, ``tmp_path`` on the path; modules imported meanwhile forgotten."""
    family = types.ModuleType("toy_families")
    family.TOYS, family.Toy = Registry("toy"), Toy
    monkeypatch.setitem(sys.modules, "toy_families", family)
    monkeypatch.setattr(registry, "_LOADER", registry._Loader())
    monkeypatch.setattr(metadata, "entry_points", lambda **kwargs: [])
    monkeypatch.syspath_prepend(str(tmp_path))
    before = set(sys.modules)
    yield family.TOYS
    for name in set(sys.modules) - before:
        del sys.modules[name]


def plug_in(monkeypatch, tmp_path, module: str, source: str) -> list[str]:
    """Write ``source`` as ``module``.py and fake one entry point of :data:`GROUP` naming it; the
    list of groups asked for, one item per call of ``entry_points``."""
    (tmp_path / f"{module}.py").write_text(textwrap.dedent(source))
    asked: list[str] = []

    def entry_points(group: str | None = None, **kwargs) -> list[metadata.EntryPoint]:
        asked.append(group)
        return [metadata.EntryPoint(name="toys", value=module, group=GROUP)] if group == GROUP else []

    monkeypatch.setattr(metadata, "entry_points", entry_points)
    return asked


def test_entries_are_found_by_name_in_registration_order():
    """register returns the entry; get, [], in, len, iteration and names follow registration order."""
    toys = Registry("toy")
    pd = toys.register(Toy("pd"))
    toys.register(Toy("lqr", 2.0))
    assert pd == Toy("pd") and toys.get("lqr").gain == 2.0 and toys["pd"] is pd
    assert toys.names() == ("pd", "lqr") and list(toys) == ["pd", "lqr"] and len(toys) == 2
    assert "pd" in toys and "pid" not in toys and dict(toys.items()) == {"pd": pd, "lqr": Toy("lqr", 2.0)}


def test_an_unknown_name_gets_the_nearest_one():
    """get and [] raise UnknownName (a KeyError) naming the family and the nearest name; a default is returned."""
    toys = Registry("controller")
    toys.register(Toy("computed_torque"))
    toys.register(Toy("sliding_mode"))
    with pytest.raises(UnknownName, match=r"unknown controller 'computed_torqe'; did you mean 'computed_torque'\?"):
        toys.get("computed_torqe")
    with pytest.raises(KeyError):
        toys["pd"]
    assert toys.get("pd", None) is None


def test_a_taken_name_is_refused_unless_replaced():
    """Registering a taken name raises InvalidArgument; replace=True swaps the entry in place."""
    toys = Registry("toy")
    toys.register(Toy("pd"))
    toys.register(Toy("lqr"))
    with pytest.raises(InvalidArgument, match="toy 'pd' is already registered"):
        toys.register(Toy("pd", 3.0))
    toys.register(Toy("pd", 3.0), replace=True)
    assert toys["pd"].gain == 3.0 and toys.names() == ("pd", "lqr")


def test_register_decorates_a_class_with_a_name():
    """@registry.register (and @registry.register(replace=True)) registers a class by its name and returns it."""
    laws = Registry("law")

    @laws.register
    class Pd:
        name = "pd"

    @laws.register(replace=True)
    class Pd2:
        name = "pd"

    assert laws["pd"] is Pd2 and isinstance(Pd, type)


def test_an_entry_without_a_name_is_refused():
    """An entry with no string name cannot be registered, and the message says so."""
    with pytest.raises(InvalidArgument, match="needs a non-empty string `name`"):
        Registry("toy").register(object())
    with pytest.raises(InvalidArgument, match="name ''"):
        Registry("toy").register(Toy(""))


def test_an_entry_point_plug_in_is_loaded_by_the_first_lookup(toys, monkeypatch, tmp_path):
    """A module named by an entry point of group freefloat.plugins registers before the first
    lookup sees the registry, and the entry points are read once per process."""
    asked = plug_in(monkeypatch, tmp_path, "toy_plugin", """
        from toy_families import TOYS, Toy
        TOYS.register(Toy("pd", 5.0))
    """)
    assert toys.get("pd").gain == 5.0
    assert "pd" in toys and toys.names() == ("pd",)
    load_plugins()
    assert asked == [GROUP]


def test_a_failing_plug_in_is_named_and_never_silent(toys, monkeypatch, tmp_path):
    """A plug-in that raises on import gives a PluginError naming its entry point and its error,
    at that lookup and at every later one."""
    plug_in(monkeypatch, tmp_path, "broken_plugin", """
        raise RuntimeError("no such gain")
    """)
    for _ in range(2):
        with pytest.raises(PluginError, match=r"plug-in 'toys' \(broken_plugin, entry point of group "
                                              r"freefloat.plugins\) failed to import: RuntimeError: no such gain"):
            toys.names()


def test_a_lookup_while_a_plug_in_loads_sees_what_it_registered(toys, monkeypatch, tmp_path):
    """A plug-in that looks up a registry while it is imported (re-entrant) sees its own entries
    and neither recurses nor deadlocks."""
    plug_in(monkeypatch, tmp_path, "curious_plugin", """
        from toy_families import TOYS, Toy
        TOYS.register(Toy("pd"))
        SEEN = TOYS.names()
        TOYS.register(Toy("pid"))
    """)
    assert toys.names() == ("pd", "pid")
    assert sys.modules["curious_plugin"].SEEN == ("pd",)


def test_a_second_thread_waits_for_the_plug_ins(toys, monkeypatch, tmp_path):
    """A lookup from another thread while the plug-ins load waits for them (it never sees half a registry)."""
    plug_in(monkeypatch, tmp_path, "slow_plugin", """
        import time
        from toy_families import TOYS, Toy
        TOYS.register(Toy("pd"))
        time.sleep(0.3)
        TOYS.register(Toy("pid"))
    """)
    seen: list[tuple[str, ...]] = []
    first = threading.Thread(target=lambda: seen.append(toys.names()))
    first.start()
    while "slow_plugin" not in sys.modules:
        time.sleep(0.001)
    seen.append(toys.names())
    first.join()
    assert seen == [("pd", "pid"), ("pd", "pid")]


def test_use_imports_a_users_file_once(toys, tmp_path):
    """use("my_pd.py", base=folder) imports the file, which registers its entry; a second use
    returns the same module (no second registration)."""
    (tmp_path / "plugins").mkdir()
    (tmp_path / "plugins" / "my_pd.py").write_text(textwrap.dedent("""
        from toy_families import TOYS, Toy
        TOYS.register(Toy("my_pd", 7.0))
    """))
    module = use("plugins/my_pd.py", base=tmp_path)
    assert toys["my_pd"].gain == 7.0 and module.__name__ == "my_pd"
    assert use(tmp_path / "plugins" / "my_pd.py") is module


def test_use_imports_a_module_by_name(toys, tmp_path):
    """use("pkg.module") imports an importable module of the user's."""
    (tmp_path / "toy_pkg").mkdir()
    (tmp_path / "toy_pkg" / "__init__.py").write_text("")
    (tmp_path / "toy_pkg" / "fields.py").write_text("from toy_families import TOYS, Toy\nTOYS.register(Toy('wind'))\n")
    assert use("toy_pkg.fields").__name__ == "toy_pkg.fields" and "wind" in toys


def test_use_refuses_what_it_cannot_import(toys, tmp_path):
    """A missing file or module, or a file named like another module, is an InvalidArgument; a
    file that raises is a PluginError naming it."""
    with pytest.raises(InvalidArgument, match="no such file"):
        use("missing.py", base=tmp_path)
    with pytest.raises(InvalidArgument, match="plug-in 'no_such_module_here': no such module"):
        use("no_such_module_here")
    (tmp_path / "json.py").write_text("")
    with pytest.raises(InvalidArgument, match="the module name 'json' is already taken"):
        use(tmp_path / "json.py")
    (tmp_path / "bad_law.py").write_text("1 / 0\n")
    with pytest.raises(PluginError, match=r"bad_law.py failed to import: ZeroDivisionError"):
        use("bad_law.py", base=tmp_path)
    assert "bad_law" not in sys.modules


def test_a_test_adds_and_removes_a_toy_by_item(monkeypatch):
    """monkeypatch.setitem registers a toy (replacing one of its name) and removes it afterwards;
    the name must be the entry's own."""
    toys = Registry("toy")
    toys.register(Toy("pd"))
    with monkeypatch.context() as patch:
        patch.setitem(toys, "lqr", Toy("lqr"))
        patch.setitem(toys, "pd", Toy("pd", 9.0))
        assert toys.names() == ("pd", "lqr") and toys["pd"].gain == 9.0
    assert toys.names() == ("pd",) and toys["pd"].gain == 1.0
    with pytest.raises(InvalidArgument, match="under its own name"):
        toys["pid"] = Toy("pd")
    with pytest.raises(UnknownName):
        del toys["pid"]


def test_a_registry_s_builtins_module_is_imported_at_its_first_lookup(tmp_path, monkeypatch):
    """A registry defined below the module that fills it imports that module at its first
    lookup, not before, and sees what it registered."""
    (tmp_path / "toy_home.py").write_text('from freefloat.registry import Registry\n'
                                          'REGISTRY = Registry("toy", builtins="toy_builtins")\n')
    (tmp_path / "toy_builtins.py").write_text('from types import SimpleNamespace\nimport toy_home\n'
                                              'toy_home.REGISTRY.register(SimpleNamespace(name="built_in"))\n')
    monkeypatch.syspath_prepend(str(tmp_path))
    for name in ("toy_home", "toy_builtins"):
        monkeypatch.delitem(sys.modules, name, raising=False)
    import toy_home

    assert "toy_builtins" not in sys.modules
    assert toy_home.REGISTRY.names() == ("built_in",)
    assert "toy_builtins" in sys.modules
