"""Structure rules of the package, read from its source (docs/architecture.md, "Structure rules").

- No private access across modules: no ``x._name`` (read, write or ``getattr``/``setattr``/
  ``hasattr``/``delattr`` with the name as a constant) where ``x`` is not ``self``/``cls`` and
  ``_name`` belongs to another module of the package, no ``from m import _name`` of another
  module, no import of a private module (``pkg._mod``) from outside its package.
- No re-exports: every import (``from m import name``), module attribute (``m.name``) and dotted
  reference in text (``fdm_awe.m.name``) of the package, the tests, the scripts, the
  documentation and the example notebooks names the module that defines the name; no module
  keeps an import it does not use or lists a foreign name in ``__all__``; only the package faces
  of :data:`PUBLIC_FACES` gather their modules' names.
- No import circle between the package's modules (module-level imports, those under
  ``if TYPE_CHECKING:`` left out: they never run).
- No module over :data:`MAX_MODULE_LINES` lines and no function over :data:`MAX_FUNCTION_LINES`
  lines, except the offenders listed here with their sizes: the lists may only shrink (an
  offender that grows fails, a new one fails, one back within the limit must leave its list).
- The MAVLink protocol modules reach the endpoint only through the members of the typed
  :class:`fdm_awe.mavlink.link.Link` interface, and the endpoint offers every one of them.

Which module a private member belongs to is decided by name: a module owns the private names it
defines (functions, classes, class-body names, module-level names, ``self.``/``cls.`` attributes
it assigns, ``__slots__`` entries, keyword names it passes, local names); ``x._name`` in a module
that does not own ``_name`` while another module of the package does is an access across modules.
A module that reads another module's ``_name`` while also defining a ``_name`` of its own is not
caught; third-party private members are not the package's (those read on purpose are listed in
:data:`THIRD_PARTY`).
"""

from __future__ import annotations

import ast
import re
import sys
from collections.abc import Callable, Iterable, Iterator
from functools import cache
from pathlib import Path

import fdm_awe

PKG = Path(fdm_awe.__file__).resolve().parent

MAX_MODULE_LINES = 500
MAX_FUNCTION_LINES = 80

#: modules over MAX_MODULE_LINES lines -> their length (lines) when the rule came in; may only shrink
LONG_MODULES: dict[str, int] = {}

#: functions over MAX_FUNCTION_LINES lines ("module:qualified name") -> (lines, why: the docstring's
#: and the code's lines as counted when the rule came in); may only shrink
LONG_FUNCTIONS: dict[str, tuple[int, str]] = {
    "api.py:optimize": (88, "docstring 53 lines (every parameter with its unit), code 30"),
    "api.py:fly": (91, "docstring 51 lines (every parameter with its unit), code 33"),
    "autopilot/auto_step.py:auto_guide": (159, "signature and docstring 11, code 148: the AUTO step numba "
                                                "compiles into the co-simulation's blocks; split into seven parts "
                                                "(bit-identical) the compiled step took 17-23 % longer (best of 40 "
                                                "and of 60 alternated rounds; its code counts references of the "
                                                "parts' array arguments: incref 60 -> 78, decref 130 -> 157)"),
    "autopilot/winch.py:cycle_winch_values": (92, "docstring 34, code 56"),
    "commands/fly.py:add_arguments": (94, "code 91: one add_argument call per option of the command"),
    "commands/sweep.py:add_arguments": (95, "code 94: one add_argument call per option of the command"),
    "groundstation/lumped_forces.py:line_forces": (91, "docstring 27, code 64: one fused pass over the segments (the "
                                                 "forces and the rest-length energy in registers), 9 % faster "
                                                 "than two loops, bit-identical"),
    "groundstation/lumped.py:inner_steps": (86, "docstring 30, code 56: a step's closing half kick fused with the "
                                                "next one's opening kick and drift (same rounding)"),
    "groundstation/substeps.py:substeps": (139, "docstring 15, code 124: the compiled sub-step loop, its sums "
                                                 "in locals (registers); its pieces are the relations above it; "
                                                 "split under 80 lines the compiled step took 2 % longer"),
    "sim/flight.py:fly": (97, "signature and docstring 57 lines (every parameter with its unit), code 40"),
}

#: private members of third-party objects read on purpose: (module, name) -> why
THIRD_PARTY: dict[tuple[str, str], str] = {
    ("jitcache.py", "_cache"): "numba's dispatcher cache: no public API names its index file",
}


def _rel(path: Path) -> str:
    return path.relative_to(PKG).as_posix()


def _module_name(path: Path) -> str:
    return ".".join(("fdm_awe", *path.relative_to(PKG).with_suffix("").parts)).removesuffix(".__init__")


@cache
def _files() -> tuple[Path, ...]:
    return tuple(sorted(PKG.rglob("*.py")))


@cache
def _tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text(), str(path))


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _is_self(node: ast.expr) -> bool:
    return isinstance(node, ast.Name) and node.id in ("self", "cls")


@cache
def _owned(path: Path) -> frozenset[str]:
    """The private names ``path`` defines (see the module docstring)."""
    names: set[str] = set()
    for n in ast.walk(_tree(path)):
        if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(n.name)
        elif isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store):
            names.add(n.id)
        elif isinstance(n, ast.Attribute) and isinstance(n.ctx, ast.Store) and _is_self(n.value):
            names.add(n.attr)
        elif isinstance(n, ast.keyword) and n.arg:
            names.add(n.arg)
        elif isinstance(n, ast.arg):
            names.add(n.arg)
        elif isinstance(n, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "__slots__" for t in n.targets):
            names.update(c.value for c in ast.walk(n.value) if isinstance(c, ast.Constant) and isinstance(c.value, str))
    return frozenset(x for x in names if _private(x))


@cache
def _package_owned() -> frozenset[str]:
    out: set[str] = set()
    for p in _files():
        out |= _owned(p)
    return frozenset(out)


def _package_of(path: Path) -> str:
    name = _module_name(path)
    return name if path.name == "__init__.py" else name.rsplit(".", 1)[0]


def _resolve(path: Path, node: ast.ImportFrom) -> str:
    """The absolute module name of ``from <module> import ...`` in ``path``."""
    if not node.level:
        return node.module or ""
    base = _package_of(path).split(".")
    base = base[: len(base) - node.level + 1]
    return ".".join(base + ([node.module] if node.module else []))


def _is_module(name: str) -> bool:
    rel = Path(*name.split(".")[1:]) if name.startswith("fdm_awe.") else None
    return rel is not None and ((PKG / rel).with_suffix(".py").is_file() or (PKG / rel / "__init__.py").is_file())


def _private_module_outside(importer: Path, name: str) -> bool:
    """``name`` (a module of the package) has a private part and ``importer`` is outside the
    package holding that part."""
    parts = name.split(".")
    own = _package_of(importer)
    for i, part in enumerate(parts):
        if _private(part):
            holder = ".".join(parts[:i])
            return not (own == holder or own.startswith(holder + "."))
    return False


def _private_accesses(path: Path) -> Iterator[str]:
    rel, owned, theirs = _rel(path), _owned(path), _package_owned()

    def foreign(name: str) -> bool:
        return _private(name) and name not in owned and name in theirs and (rel, name) not in THIRD_PARTY

    for n in ast.walk(_tree(path)):
        if isinstance(n, ast.Attribute) and not _is_self(n.value) and foreign(n.attr):
            yield f"{rel}:{n.lineno}: {ast.unparse(n)}"
        elif (isinstance(n, ast.Call) and isinstance(n.func, ast.Name)
              and n.func.id in ("getattr", "setattr", "hasattr", "delattr") and len(n.args) >= 2
              and isinstance(n.args[1], ast.Constant) and isinstance(n.args[1].value, str)
              and not _is_self(n.args[0]) and foreign(n.args[1].value)):
            yield f"{rel}:{n.lineno}: {ast.unparse(n)}"
        elif isinstance(n, ast.ImportFrom):
            module = _resolve(path, n)
            if not module.startswith("fdm_awe"):
                continue
            if _private_module_outside(path, module):
                yield f"{rel}:{n.lineno}: from {module} import ..."
                continue
            for a in n.names:
                if not _private(a.name):
                    continue
                sub = f"{module}.{a.name}"
                if _is_module(sub):  # a private module: only its own package imports it
                    if _private_module_outside(path, sub):
                        yield f"{rel}:{n.lineno}: from {module} import {a.name}"
                elif module != _module_name(path):
                    yield f"{rel}:{n.lineno}: from {module} import {a.name}"
        elif isinstance(n, ast.Import):
            for a in n.names:
                if a.name.startswith("fdm_awe") and _private_module_outside(path, a.name):
                    yield f"{rel}:{n.lineno}: import {a.name}"


def test_no_private_access_across_modules() -> None:
    bad = [line for p in _files() for line in _private_accesses(p)]
    assert not bad, "private members of other modules used:\n" + "\n".join(bad)


def test_the_private_access_check_sees_what_it_must(tmp_path, monkeypatch) -> None:
    """The check itself: a read, a write, a getattr and an import of another module's private
    names are found; ``self._x``, the module's own ``obj._x`` and public names are not."""
    (tmp_path / "a.py").write_text("class A:\n    def __init__(self):\n        self._x = 1\n\n"
                                   "def _helper():\n    return 0\n\ndef peer(o):\n    return o._x\n")
    (tmp_path / "b.py").write_text("from .a import _helper, peer\n\ndef f(o):\n    o._x = 2\n"
                                   "    return o._x + getattr(o, '_x') + peer(o) + o.public + o.__class__.x\n")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "__init__.py").write_text("")
    (tmp_path / "sub" / "_hid.py").write_text("X = 1\n")
    (tmp_path / "sub" / "d.py").write_text("from . import _hid\n")  # its own package: allowed
    (tmp_path / "c.py").write_text("from .sub import _hid\nfrom .sub._hid import X\n")
    caches = (_files, _tree, _owned, _package_owned)
    monkeypatch.setattr(sys.modules[__name__], "PKG", tmp_path)
    for f in caches:
        f.cache_clear()
    try:
        found = {p.name: sorted(line.split(": ", 1)[1] for line in _private_accesses(p)) for p in _files()}
    finally:
        monkeypatch.undo()
        for f in caches:
            f.cache_clear()
    assert found == {"a.py": [], "b.py": sorted(["from fdm_awe.a import _helper", "o._x", "o._x", "getattr(o, '_x')"]),
                     "c.py": ["from fdm_awe.sub import _hid", "from fdm_awe.sub._hid import ..."],
                     "d.py": [], "__init__.py": [], "_hid.py": []}


def _module_level_imports(path: Path) -> set[str]:
    """The package's modules that ``path`` imports when it is imported (module level, also
    under ``try``/``if``; not under ``if TYPE_CHECKING:``)."""
    out: set[str] = set()

    def visit(body: list[ast.stmt]) -> None:
        for st in body:
            if isinstance(st, ast.If):
                test = ast.unparse(st.test)
                if test in ("TYPE_CHECKING", "typing.TYPE_CHECKING"):
                    visit(st.orelse)
                    continue
                visit(st.body)
                visit(st.orelse)
            elif isinstance(st, ast.Try):
                for b in (st.body, st.orelse, st.finalbody, *(h.body for h in st.handlers)):
                    visit(b)
            elif isinstance(st, (ast.With,)):
                visit(st.body)
            elif isinstance(st, ast.Import):
                out.update(a.name for a in st.names if a.name.startswith("fdm_awe"))
            elif isinstance(st, ast.ImportFrom):
                module = _resolve(path, st)
                if not module.startswith("fdm_awe"):
                    continue
                subs = [f"{module}.{a.name}" for a in st.names if _is_module(f"{module}.{a.name}")]
                out.update(subs)
                if len(subs) < len(st.names):  # names defined in the module (or package) itself
                    out.add(module)

    visit(_tree(path).body)
    return {m for m in out if _is_module(m)}


def _circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (or a module importing itself)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = [0]

    def strong(v: str) -> None:  # Tarjan
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1 or v in graph.get(v, ()):
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            strong(v)
    return out


def test_no_import_circle() -> None:
    graph = {_module_name(p): _module_level_imports(p) - {_module_name(p)} for p in _files()}
    assert sum(len(v) for v in graph.values()) > 200  # the graph was read
    circles = _circles(graph)
    assert not circles, "import circles:\n" + "\n".join(" <-> ".join(c) for c in circles)


def test_the_circle_finder_finds_a_circle() -> None:
    assert _circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _circles({"a": {"b"}, "b": set()}) == []


def test_module_length() -> None:
    lengths = {_rel(p): len(p.read_text().splitlines()) for p in _files()}
    new = {m: n for m, n in lengths.items() if n > MAX_MODULE_LINES and m not in LONG_MODULES}
    grown = {m: (n, LONG_MODULES[m]) for m, n in lengths.items() if m in LONG_MODULES and n > LONG_MODULES[m]}
    back = sorted(m for m in LONG_MODULES if lengths.get(m, 0) <= MAX_MODULE_LINES)
    assert not new, f"modules over {MAX_MODULE_LINES} lines: {new}"
    assert not grown, f"listed long modules grew (now, listed): {grown}"
    assert not back, f"within {MAX_MODULE_LINES} lines now (or gone): remove from LONG_MODULES: {back}"


def _functions(path: Path, measure: Callable[[ast.AST], int]) -> Iterator[tuple[str, int]]:
    """Every function of ``path`` by qualified name, with ``measure`` of its node."""
    def walk(node: ast.AST, prefix: str) -> Iterator[tuple[str, int]]:
        for c in ast.iter_child_nodes(node):
            if isinstance(c, (ast.FunctionDef, ast.AsyncFunctionDef)):
                q = prefix + c.name
                yield q, measure(c)
                yield from walk(c, q + ".<locals>.")
            elif isinstance(c, ast.ClassDef):
                yield from walk(c, prefix + c.name + ".")
            else:
                yield from walk(c, prefix)

    yield from walk(_tree(path), "")


def _function_lengths(path: Path) -> Iterator[tuple[str, int]]:
    return _functions(path, lambda f: f.end_lineno - f.lineno + 1)


def test_function_length() -> None:
    lengths = {f"{_rel(p)}:{q}": n for p in _files() for q, n in _function_lengths(p)}
    assert len(lengths) > 1000  # every function was read
    new = {f: n for f, n in lengths.items() if n > MAX_FUNCTION_LINES and f not in LONG_FUNCTIONS}
    grown = {f: (n, LONG_FUNCTIONS[f][0]) for f, n in lengths.items() if f in LONG_FUNCTIONS and n > LONG_FUNCTIONS[f][0]}
    back = sorted(f for f in LONG_FUNCTIONS if lengths.get(f, 0) <= MAX_FUNCTION_LINES)
    assert not new, f"functions over {MAX_FUNCTION_LINES} lines: {new}"
    assert not grown, f"listed long functions grew (now, listed): {grown}"
    assert not back, f"within {MAX_FUNCTION_LINES} lines now (or gone): remove from LONG_FUNCTIONS: {back}"


# --- no re-exports: every name is imported from the module that defines it ---------------------

#: the package's public faces: ``__init__`` modules that gather their package's names on purpose
#: (users import ``from fdm_awe.trajectory import read_reference``) -> what they offer; nowhere
#: else is a name imported from a module that does not define it
PUBLIC_FACES: dict[str, str] = {
    "fdm_awe": "the Python API on the package's top level (the names of fdm_awe.api and fdm_awe.api_results, "
               "looked up on first use)",
    "fdm_awe.groundstation": "the ground station, its parameters' loader and its steady-state relations",
    "fdm_awe.mavlink": "the link's vocabulary: the autopilot's vehicle interface, parameters and modes, the geo frame",
    "fdm_awe.recording": "the recordings' one-line entry points (looked up on first use)",
    "fdm_awe.sixdof": "the JSBSim glider, its state and surfaces, the stabiliser",
    "fdm_awe.trajectory": "the reference trajectory: its schema, files, checks and sampler",
}

#: the repository's other Python sources checked for imports through a re-export (besides the package)
OTHER_SOURCES = ("tests", "scripts", "examples", "docs")


@cache
def _defined(path: Path) -> frozenset[str]:
    """The names ``path`` binds at module level other than by an import (functions, classes,
    assignments, loop and ``with`` targets; also under ``if``/``try``)."""
    out: set[str] = set()

    def targets(node: ast.AST) -> None:
        out.update(n.id for n in ast.walk(node) if isinstance(n, ast.Name))

    def visit(body: list[ast.stmt]) -> None:
        for st in body:
            if isinstance(st, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                out.add(st.name)
            elif isinstance(st, ast.Assign):
                for t in st.targets:
                    targets(t)
            elif isinstance(st, (ast.AnnAssign, ast.AugAssign, ast.For)):
                targets(st.target)
            elif isinstance(st, ast.With):
                for item in st.items:
                    if item.optional_vars is not None:
                        targets(item.optional_vars)
            if isinstance(st, (ast.If, ast.Try, ast.With, ast.For, ast.While)):
                for b in (st.body, getattr(st, "orelse", []), getattr(st, "finalbody", []),
                          *(h.body for h in getattr(st, "handlers", []))):
                    visit(b)

    visit(_tree(path).body)
    return frozenset(out)


def _module_path(name: str) -> Path | None:
    """The file of the package's module ``name`` (``fdm_awe.a.b``), None if it is none."""
    if name != "fdm_awe" and not name.startswith("fdm_awe."):
        return None
    rel = Path(*name.split(".")[1:])
    for p in ((PKG / rel / "__init__.py"), (PKG / rel).with_suffix(".py")):
        if p.is_file():
            return p
    return None


def _not_defined(module: str, name: str, faces: Iterable[str]) -> bool:
    """``name`` taken from the package's module ``module`` is neither a sub-module nor defined
    there, and ``module`` is not a public face."""
    path = _module_path(module)
    return (path is not None and module not in faces and _module_path(f"{module}.{name}") is None
            and not (name.startswith("__") and name.endswith("__")) and name not in _defined(path))


def _reexport_uses(label: str, tree: ast.Module, path: Path | None, faces: Iterable[str]) -> Iterator[str]:
    """``from m import name`` and ``m.name`` (``m`` a module of the package, bound by an import)
    in ``tree`` where ``m`` does not define ``name`` (``path``: the package file of ``tree``,
    for its relative imports; None outside the package)."""
    aliases: dict[str, str] = {}  # name bound by an import -> the package's module it holds
    for n in ast.walk(tree):
        if isinstance(n, ast.Import):
            for a in n.names:
                if _module_path(a.name) is not None:
                    aliases[a.asname or a.name.split(".")[0]] = a.name if a.asname else a.name.split(".")[0]
        elif isinstance(n, ast.ImportFrom):
            module = _resolve(path, n) if path is not None else (n.module or "")
            for a in n.names:
                if _module_path(f"{module}.{a.name}") is not None:
                    aliases[a.asname or a.name] = f"{module}.{a.name}"
                elif _not_defined(module, a.name, faces):
                    yield f"{label}:{n.lineno}: from {module} import {a.name}"

    def held(node: ast.expr) -> str | None:  # the package's module an expression names, if any
        if isinstance(node, ast.Name):
            return aliases.get(node.id)
        if isinstance(node, ast.Attribute):
            base = held(node.value)
            sub = f"{base}.{node.attr}" if base else None
            return sub if sub and _module_path(sub) is not None else None
        return None

    for n in ast.walk(tree):
        if isinstance(n, ast.Attribute):
            module = held(n.value)
            if module and _not_defined(module, n.attr, faces):
                yield f"{label}:{n.lineno}: {ast.unparse(n)}"


def _used_names(tree: ast.Module) -> set[str]:
    """The names ``tree`` reads (also inside string annotations), ``__all__``'s strings left out."""
    used = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}
    notes = [n.annotation for n in ast.walk(tree) if isinstance(n, (ast.arg, ast.AnnAssign)) and n.annotation]
    notes += [n.returns for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)) and n.returns]
    for note in notes:
        for c in ast.walk(note):
            if isinstance(c, ast.Constant) and isinstance(c.value, str):
                try:
                    used |= {x.id for x in ast.walk(ast.parse(c.value, mode="eval")) if isinstance(x, ast.Name)}
                except SyntaxError:
                    pass
    return used


def _reexports(path: Path, faces: Iterable[str]) -> Iterator[str]:
    """A module (not a public face) that hands on names of others: a name imported from the
    package at module level and not used, or one in its ``__all__`` that it does not define."""
    if _module_name(path) in faces:
        return
    tree, rel = _tree(path), _rel(path)
    used = _used_names(tree)
    for st in _module_level(tree.body):
        if isinstance(st, ast.ImportFrom):
            module = _resolve(path, st)
            for a in st.names:
                name = a.asname or a.name
                if _module_path(module) is not None and _module_path(f"{module}.{a.name}") is None and name not in used:
                    yield f"{rel}:{st.lineno}: {name} imported from {module}, not used"
        elif isinstance(st, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "__all__" for t in st.targets):
            for c in ast.walk(st.value):
                if isinstance(c, ast.Constant) and isinstance(c.value, str) and c.value not in _defined(path):
                    yield f"{rel}:{st.lineno}: __all__ names {c.value}, defined elsewhere"


def _module_level(body: list[ast.stmt]) -> Iterator[ast.stmt]:
    """The statements of a module's body, also those under ``if``/``try``."""
    for st in body:
        yield st
        if isinstance(st, (ast.If, ast.Try)):
            for b in (st.body, st.orelse, getattr(st, "finalbody", []), *(h.body for h in getattr(st, "handlers", []))):
                yield from _module_level(b)


def _other_sources() -> Iterator[tuple[str, ast.Module]]:
    """(label, syntax tree) of the repository's Python sources outside the package: the tests,
    scripts and documentation's Python files, and the code cells of the example notebooks."""
    import json

    root = PKG.parent
    for folder in OTHER_SOURCES:
        for p in sorted((root / folder).rglob("*.py")):
            yield p.relative_to(root).as_posix(), ast.parse(p.read_text(), str(p))
        for p in sorted((root / folder).rglob("*.ipynb")):
            cells = json.loads(p.read_text()).get("cells", [])
            for i, c in enumerate(cells):
                if c.get("cell_type") == "code":
                    src = "".join(c.get("source", []))
                    src = "\n".join("" if ln.lstrip().startswith(("%", "!")) else ln for ln in src.splitlines())
                    yield f"{p.relative_to(root).as_posix()}[cell {i}]", ast.parse(src)


#: a dotted name of the package in text (docstrings, comments, documentation)
DOTTED = re.compile(r"\bfdm_awe(?:\.[A-Za-z_]\w*)+")


def _dotted_references(label: str, text: str, faces: Iterable[str]) -> Iterator[str]:
    """Dotted names ``fdm_awe.m.name`` in ``text`` whose module ``m`` does not define ``name``."""
    for i, line in enumerate(text.splitlines(), 1):
        for m in DOTTED.finditer(line):
            parts = m.group(0).split(".")
            k = max(j for j in range(1, len(parts) + 1) if _module_path(".".join(parts[:j])) is not None)
            if k < len(parts) and _not_defined(".".join(parts[:k]), parts[k], faces):
                yield f"{label}:{i}: {m.group(0)}"


def test_no_reexports() -> None:
    """No module hands on names it imports (except the public faces), and every import, module
    attribute and dotted reference of the repository names the module that defines the name."""
    faces = tuple(PUBLIC_FACES)
    bad = [line for p in _files() for line in _reexports(p, faces)]
    bad += [line for p in _files() for line in _reexport_uses(_rel(p), _tree(p), p, faces)]
    bad += [line for label, tree in _other_sources() for line in _reexport_uses(label, tree, None, faces)]
    root = PKG.parent
    texts = [(_rel(p), p.read_text()) for p in _files()]
    texts += [(p.relative_to(root).as_posix(), p.read_text()) for folder in ("tests", "scripts")
              for p in sorted((root / folder).rglob("*.py"))]
    texts += [(p.relative_to(root).as_posix(), p.read_text())
              for p in [root / "README.md", *sorted((root / "docs").rglob("*.md"))]]
    bad += [line for label, text in texts for line in _dotted_references(label, text, faces)]
    assert not bad, ("names taken from a module that does not define them (import them from their own module):\n"
                     + "\n".join(bad))


def test_the_reexport_check_sees_what_it_must(tmp_path, monkeypatch) -> None:
    """The check itself, on a generated package: a re-export through ``__all__``, an unused
    import kept for old imports, an import, a module attribute and a dotted reference through a
    module that does not define the name are found; the defining module's path, a public face,
    a sub-module and a name used in a string annotation are not."""
    (tmp_path / "a.py").write_text("X = 1\n\ndef f():\n    return X\n")
    (tmp_path / "b.py").write_text("from .a import X, f\n\n__all__ = ['X', 'g']\n\ndef g():\n    return X + f()\n")
    (tmp_path / "shim.py").write_text("from .a import f  # kept for old imports\n")
    (tmp_path / "c.py").write_text("from .b import X\nfrom . import b, a\n\n\ndef h() -> 'f':\n"
                                   "    return X + b.X + b.g() + a.X  # see fdm_awe.b.X and fdm_awe.a.X\n")
    (tmp_path / "face").mkdir()
    (tmp_path / "face" / "__init__.py").write_text("from ..a import X\n")
    (tmp_path / "face" / "m.py").write_text("Y = 2\n")
    (tmp_path / "d.py").write_text("from .face import X, m\nfrom .face.m import Y\nimport fdm_awe.face.m\n\n"
                                   "Z = X + Y + m.Y + fdm_awe.face.m.Y\n")
    (tmp_path / "e.py").write_text("from typing import TYPE_CHECKING\n\nif TYPE_CHECKING:\n    from .a import f\n\n\n"
                                   "def k(x: 'f') -> None:\n    pass\n")
    monkeypatch.setattr(sys.modules[__name__], "PKG", tmp_path)
    caches = (_files, _tree, _defined)
    for f in caches:
        f.cache_clear()
    faces = ("fdm_awe", "fdm_awe.face")
    try:
        found = {p.name: sorted(line.split(": ", 1)[1] for line in (*_reexports(p, faces), *_reexport_uses(
            _rel(p), _tree(p), p, faces), *_dotted_references(_rel(p), p.read_text(), faces))) for p in _files()}
    finally:
        monkeypatch.undo()
        for f in caches:
            f.cache_clear()
    assert found == {"a.py": [], "b.py": ["__all__ names X, defined elsewhere"],
                     "shim.py": ["f imported from fdm_awe.a, not used"],
                     "c.py": sorted(["from fdm_awe.b import X", "b.X", "fdm_awe.b.X"]),
                     "__init__.py": [], "m.py": [], "d.py": [], "e.py": []}


#: the MAVLink protocol modules: handed the endpoint, they use it as a :class:`~fdm_awe.mavlink.link.Link`
PROTOCOL_MODULES = ("commands", "ftp", "messages", "mission", "param_protocol", "pilot", "signing", "statustext",
                    "streams", "winch")


def _link_members() -> set[str]:
    from fdm_awe.mavlink.link import Link

    return {n for n in dir(Link) if not n.startswith("_")} | set(Link.__annotations__)


def _link_uses(path: Path) -> tuple[set[str], set[str]]:
    """(names of ``path`` that hold the link, members used on them): parameters annotated
    ``Link``, ``self.<x>`` assigned from one, and locals assigned from ``self.<x>``."""
    tree = _tree(path)
    params = {n.arg for n in ast.walk(tree) if isinstance(n, ast.arg) and n.annotation is not None
              and ast.unparse(n.annotation).strip("'\"") == "Link"}
    fields = {t.attr for n in ast.walk(tree) if isinstance(n, ast.Assign) and isinstance(n.value, ast.Name)
              and n.value.id in params for t in n.targets if isinstance(t, ast.Attribute) and _is_self(t.value)}
    names = params | {t.id for n in ast.walk(tree) if isinstance(n, ast.Assign) and isinstance(n.value, ast.Attribute)
                      and _is_self(n.value.value) and n.value.attr in fields for t in n.targets
                      if isinstance(t, ast.Name)}
    used = set()
    for n in ast.walk(tree):
        if isinstance(n, ast.Attribute):
            v = n.value
            if (isinstance(v, ast.Name) and v.id in names) or (
                    isinstance(v, ast.Attribute) and _is_self(v.value) and v.attr in fields):
                used.add(n.attr)
    return names, used


def test_the_protocol_modules_use_the_endpoint_as_a_link() -> None:
    members = _link_members()
    assert {"send", "mav", "statustext", "telemetry", "vehicle"} <= members
    seen: set[str] = set()
    for name in PROTOCOL_MODULES:
        path = PKG / "mavlink" / f"{name}.py"
        assert "MavlinkEndpoint\"" not in path.read_text() and ".endpoint import" not in path.read_text(), name
        names, used = _link_uses(path)
        assert names, f"mavlink/{name}.py: no parameter annotated Link"
        assert used <= members, f"mavlink/{name}.py uses {sorted(used - members)} beyond the Link interface"
        seen |= used
    assert seen == members, f"members of Link no protocol module uses: {sorted(members - seen)}"


def test_the_endpoint_is_a_link() -> None:
    import socket

    from fdm_awe.mavlink.endpoint import MavlinkEndpoint
    from fdm_awe.mavlink.link import Link

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:  # a free port; nobody needs to listen
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    ep = MavlinkEndpoint(f"udpout:127.0.0.1:{port}")
    try:
        assert isinstance(ep, Link)
        missing = sorted(n for n in _link_members() if not hasattr(ep, n))
        assert not missing, missing
        for n in ("telemetry", "for_me", "send", "set_rate", "statustext", "wake", "info", "warn"):
            assert callable(getattr(ep, n)), n
        assert isinstance(ep.link_lost, bool) and isinstance(ep.stats, dict) and isinstance(ep.sysid, int)
    finally:
        ep.close()
    assert not isinstance(object(), Link)


# -- named slots: the compiled core's layouts are declared (fdm_awe.slots), not hand-kept --------

#: modules that still keep array offsets by hand -> how many hand-kept offset blocks (module-level
#: ``A, B, C = range(n)`` unpackings, integer constants the module uses as an index); may only shrink
HAND_OFFSETS: dict[str, int] = {}

#: most positional parameters a function of the package takes (the compiled core passes blocks)
MAX_POSITIONAL = 15

#: functions with more positional parameters -> (count, reason); may only shrink
LONG_SIGNATURES: dict[str, tuple[int, str]] = {
    "autopilot/attitude.py:attitude_commands": (19, "compiled relation of floats"),
    "autopilot/guidance.py:_command": (17, "compiled relation of floats"),
    "autopilot/guidance.py:_traded_lift": (16, "compiled relation of floats"),
    "autopilot/winch.py:cycle_winch_values": (20, "compiled relation of floats"),
    "groundstation/linemodels.py:line_step": (16, "the line models' one step signature"),
    "groundstation/station_output.py:_set_slots": (19, "one slot per output"),
    "groundstation/station_output.py:GroundStationOutput.__init__": (17, "one slot per output"),
    "groundstation/substeps.py:hold_current": (20, "compiled relation of floats"),
    "groundstation/substeps.py:hold_generator": (22, "compiled relation of floats"),
    "groundstation/substeps.py:advance": (16, "the drivetrain's step: the line model's step arguments and "
                                              "the prescribed tension"),
    "groundstation/winch.py:drum_step": (17, "compiled relation of floats"),
    "groundstation/winch.py:end_stop": (17, "compiled relation of floats"),
    "sim/flight.py:fly": (16, "the flight's options"),
    "sixdof/attitude_law.py:law_commands": (18, "compiled relation of floats"),
}


def _hand_offsets(path: Path) -> int:
    tree = _tree(path)
    count = 0
    ints: set[str] = set()
    for node in tree.body:
        if not isinstance(node, ast.Assign) or len(node.targets) != 1:
            continue
        value, target = node.value, node.targets[0]
        if isinstance(value, ast.Call) and isinstance(value.func, ast.Name) and value.func.id == "range":
            count += 1
        elif (isinstance(target, ast.Name) and target.id.isupper() and isinstance(value, ast.Constant)
              and type(value.value) is int):
            ints.add(target.id)
    used = {s.slice.id for s in ast.walk(tree) if isinstance(s, ast.Subscript) and isinstance(s.slice, ast.Name)}
    return count + (1 if ints & used else 0)


def test_no_hand_kept_offsets() -> None:
    found = {_rel(p): n for p in _files() if (n := _hand_offsets(p))}
    new = {m: n for m, n in found.items() if m not in HAND_OFFSETS}
    grown = {m: (n, HAND_OFFSETS[m]) for m, n in found.items() if m in HAND_OFFSETS and n > HAND_OFFSETS[m]}
    shrunk = {m: (found.get(m, 0), n) for m, n in HAND_OFFSETS.items() if found.get(m, 0) < n}
    assert not new, f"hand-kept offsets (declare the layout with fdm_awe.slots): {new}"
    assert not grown, f"more hand-kept offsets (now, listed): {grown}"
    assert not shrunk, f"fewer hand-kept offsets now: lower HAND_OFFSETS (now, listed): {shrunk}"


def test_the_offset_check_sees_what_it_must(tmp_path) -> None:
    p = tmp_path / "m.py"
    p.write_text("A, B = range(2)\nC = 3\n\ndef f(x):\n    return x[C] + x[A]\n")
    assert _hand_offsets(p) == 2
    p = tmp_path / "n.py"  # another file: trees are cached by path
    p.write_text("from fdm_awe import slots\nL = slots.declare('L', ('a', 'b'))\nN = 3\n\n"
                 "def f(x):\n    return x[L.a] * N\n")
    assert _hand_offsets(p) == 0


def _signatures(path: Path) -> Iterator[tuple[str, int]]:
    return _functions(path, lambda f: len(f.args.posonlyargs) + len(f.args.args))


def test_signature_length() -> None:
    counts = {f"{_rel(p)}:{q}": n for p in _files() for q, n in _signatures(p)}
    new = {f: n for f, n in counts.items() if n > MAX_POSITIONAL and f not in LONG_SIGNATURES}
    grown = {f: (n, LONG_SIGNATURES[f][0]) for f, n in counts.items() if f in LONG_SIGNATURES and n > LONG_SIGNATURES[f][0]}
    shrunk = {f: (counts.get(f, 0), v[0]) for f, v in LONG_SIGNATURES.items() if counts.get(f, 0) < v[0]}
    assert not new, f"functions over {MAX_POSITIONAL} positional parameters (pass a block): {new}"
    assert not grown, f"listed long signatures grew (now, listed): {grown}"
    assert not shrunk, f"shorter now: lower or remove in LONG_SIGNATURES (now, listed): {shrunk}"
