"""The race's scenes in MuJoCo's terms: ``mjcf`` (a Pinocchio tree as MJCF, inertias balanced
where MuJoCo refuses them), ``state`` (states both ways), ``wrenches`` (external wrenches as
``xfrc_applied``), ``mechanism_mjcf`` and ``mechanism`` (a closed chain: its MJCF and its runs)."""

from ....lazy import lazy_modules  # noqa: E402

__getattr__ = lazy_modules(__name__)  # its modules, imported on first use as attributes
