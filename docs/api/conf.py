"""Sphinx configuration of the fdm-awe API documentation (built from the docstrings).

Build: ``python -m sphinx -W -b html docs/api OUT`` from the repository root (warnings are
errors; ``tests/test_api_docs.py`` builds it so).
"""

from __future__ import annotations

import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))  # the checkout's package

import fdm_awe  # noqa: E402

project = "fdm-awe"
author = "the fdm-awe authors"
copyright = "the fdm-awe authors, MIT licence"
version = release = fdm_awe.__version__

extensions = ["sphinx.ext.autodoc", "sphinx.ext.napoleon"]
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "undoc-members": False}
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False
napoleon_use_ivar = True  # "Attributes" as fields of the class, not second descriptions of the dataclass fields
# the types named in docstrings are the package's own or numpy's; not cross-checked
nitpicky = False
exclude_patterns = ["_build"]
html_theme = "alabaster"
html_static_path: list[str] = []
