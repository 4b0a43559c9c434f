"""Build step of fdm-awe: everything else is declared in pyproject.toml.

The definition folders ``aircraft/``, ``engine/`` and ``tether/`` stay at the top level of the
repository (a JSBSim root: JSBSim finds ``aircraft/NAME/NAME.xml`` and ``engine/*.xml`` below
one folder). Every wheel and sdist carries them as package data below ``fdm_awe/data/``, so an
installed ``fdm_awe`` finds the same files there (``fdm_awe.ROOT``, docs/design.md section 2).
The example references (``fdm_awe.example_refs.EXAMPLES``, stored in ``tests/data/``) ship as
``fdm_awe/data/examples/`` (``--reference example:nominal-8``).
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


def example_files() -> list[str]:
    """The files of ``fdm_awe.example_refs.EXAMPLES`` (read from its source, not imported: the
    build does not import the package), shipped from ``tests/data/`` as ``fdm_awe/data/examples/``."""
    import ast

    tree = ast.parse((HERE / "fdm_awe" / "example_refs.py").read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "EXAMPLES" for t in node.targets):
            return sorted(ast.literal_eval(node.value).values())
    raise RuntimeError("fdm_awe/example_refs.py defines no EXAMPLES")


DATA = definition_packages()
EXAMPLES_PACKAGE = "fdm_awe.data.examples"

setup(
    packages=find_packages(include=["fdm_awe", "fdm_awe.*"]) + list(DATA) + [EXAMPLES_PACKAGE],
    package_dir={**{name: DATA[name] for name in DATA if name.count(".") == 2}, EXAMPLES_PACKAGE: "tests/data"},
    package_data={**{name: ["*.xml"] for name in DATA}, EXAMPLES_PACKAGE: example_files()},
    include_package_data=False,  # exactly the files named above (tests/data holds more than the examples)
)
