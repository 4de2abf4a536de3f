"""The fuzz corpus by class (issue 24): each class makes case ``seed`` from its seed alone, and each
case has a ``kind``, a ``mutation`` (what was done) and ``run(folder) -> (outcome, detail)``.
``scripts/fuzz.py`` runs the whole corpus and counts outcomes per class; ``tests/test_fuzz.py`` a
slice of each class.
"""

from __future__ import annotations

from .fuzzing import GOOD, scene_case, urdf_case
from .fuzzing_api import api_case
from .fuzzing_folders import folders_case, links_case
from .fuzzing_pages import texture_case
from .fuzzing_signals import signal_case

#: Class name -> case maker: mutated URDFs and scenes through ``freefloat simulate``; output
#: folders holding a user's files or symbolic links; URL textures in pages; signals at
#: checkpoints; Python API calls with hostile arguments.
CLASSES = {"urdf": urdf_case, "scene": scene_case, "folders": folders_case, "links": links_case,
           "textures": texture_case, "signals": signal_case, "api": api_case}

__all__ = ["CLASSES", "GOOD"]
