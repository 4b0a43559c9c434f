"""Build step of fdm-awe: everything else is declared in pyproject.toml.

The definition folders ``aircraft/``, ``engine/`` and ``tether/`` stay at the top level of the
repository (a JSBSim root: JSBSim finds ``aircraft/NAME/NAME.xml`` and ``engine/*.xml`` below
one folder). Every wheel and sdist carries them as package data below ``fdm_awe/data/``, so an
installed ``fdm_awe`` finds the same files there (``fdm_awe.ROOT``, docs/design.md section 2).
The mapping is declared here, not in pyproject.toml, because ``find_packages`` then keeps
discovering the package's own sub-packages while the definition folders are added to them.
"""

from pathlib import Path

from setuptools import find_packages, setup

HERE = Path(__file__).resolve().parent

#: Top-level definition folders shipped as ``fdm_awe/data/<folder>/`` (the same names as
#: ``fdm_awe.DEFINITION_FOLDERS``; tests/test_packaging.py checks that).
DEFINITION_FOLDERS = ("aircraft", "engine", "tether")


def definition_packages() -> dict[str, str]:
    """Package name -> source folder for every folder below the definition folders."""
    packages = {}
    for folder in DEFINITION_FOLDERS:
        for sub in sorted([HERE / folder, *(p for p in (HERE / folder).rglob("*") if p.is_dir())]):
            rel = sub.relative_to(HERE)
            packages["fdm_awe.data." + ".".join(rel.parts)] = rel.as_posix()
    return packages


DATA = definition_packages()

setup(
    packages=find_packages(include=["fdm_awe", "fdm_awe.*"]) + list(DATA),
    package_dir={name: DATA[name] for name in DATA if name.count(".") == 2},
    package_data={name: ["*.xml"] for name in DATA},
)
