"""Build step of fdm-awe: everything else is declared in pyproject.toml.

The definition folders ``aircraft/``, ``engine/`` and ``tether/`` stay at the top level of the
repository (a JSBSim root: JSBSim finds ``aircraft/NAME/NAME.xml`` and ``engine/*.xml`` below
one folder). Every wheel and sdist carries them as package data below ``fdm_awe/data/``, so an
installed ``fdm_awe`` finds the same files there (``fdm_awe.ROOT``, docs/design.md section 2).
The example references (``fdm_awe.example_refs.EXAMPLES``, stored in ``tests/data/``) ship as
``fdm_awe/data/examples/`` (``--reference example:nominal-8``).
The mapping is declared here, not in pyproject.toml, because ``find_packages`` then keeps
discovering the package's own sub-packages while the definition folders are added to them.
The package index shows README.md as the long description with its relative links made
absolute (:func:`index_readme`): on the index page a link to ``docs/design.md`` has no
repository to resolve against.
"""

import re
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


#: where the README's relative links point on the package index page: files (and folders) at
#: the repository's main branch, images as their raw files
BLOB_URL = "https://github.com/fdm-awe/fdm-awe/blob/main/"
RAW_URL = "https://raw.githubusercontent.com/fdm-awe/fdm-awe/main/"
_LINK = re.compile(r"(!?)\[([^\]]*)\]\(([^)\s]+)\)")


def index_readme(text: str) -> str:
    """``text`` (Markdown) with every relative link and image made absolute: links to
    :data:`BLOB_URL`, images to :data:`RAW_URL`; absolute URLs and in-page anchors stay."""

    def absolute(m: re.Match) -> str:
        bang, label, target = m.groups()
        if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I) or target.startswith("#"):
            return m.group(0)
        return f"{bang}[{label}]({(RAW_URL if bang else BLOB_URL) + target.lstrip('./')})"

    return _LINK.sub(absolute, text)


DATA = definition_packages()
EXAMPLES_PACKAGE = "fdm_awe.data.examples"

if __name__ == "__main__":  # the build runs this file as __main__; tests import index_readme
    setup(
        long_description=index_readme((HERE / "README.md").read_text(encoding="utf-8")),
        long_description_content_type="text/markdown",
        packages=find_packages(include=["fdm_awe", "fdm_awe.*"]) + list(DATA) + [EXAMPLES_PACKAGE],
        package_dir={**{name: DATA[name] for name in DATA if name.count(".") == 2}, EXAMPLES_PACKAGE: "tests/data"},
        package_data={**{name: ["*.xml"] for name in DATA}, EXAMPLES_PACKAGE: example_files()},
        include_package_data=False,  # exactly the files named above (tests/data holds more than the examples)
    )
