"""Every command line documented in README.md and docs/*.md runs.

The lines are extracted automatically (:func:`documented_commands`): every line of a fenced code
block, and every inline code span outside them that holds a whole command (an option or a file
argument after the program), that starts with ``fdm-awe``, ``python scripts/``, ``rerun``,
``bash scripts/`` or ``mavproxy.py`` (each optionally behind ``.venv/bin/``). A ``# comment`` at
the end is dropped; a line ``PROG ... --more`` repeats the previous full ``PROG`` line of its
code block with ``--more`` added.

Each line gets a plan (:func:`plan`), shown in its test id and by ``test_plan_table``:

``run``      as written;
``variant``  a short variant, each change named: ``fly`` one cycle (``--cycles 1``),
             ``--realtime`` at 100x, ``--mavlink`` to a UDP socket of the test (which must
             receive MAVLink 2 frames), the optimisers on a coarse mesh (``--mesh``), a sweep
             reduced to one nominal point at 8 m/s on one worker, prose lines and scripts that
             optimise a case a stored reference of ``tests/data`` holds fly that reference,
             the line calibration on one point (nominal, 10 m/s, one cycle), the grid,
             line-comparison and drive-map scripts on their smallest grids,
             ``rerun FILE`` (the viewer) as ``rerun rrd verify FILE``;
``parse``    checked without running: shell scripts with ``bash -n`` (``run_tests.sh`` runs this
             test, ``run_demo.sh`` and ``setup.sh`` install packages), ``fdm-awe`` lines that
             need an outside server (``--scheduler``) by the command line's own parser,
             programs of other projects (MAVProxy) and benchmarks with ``--help``;
``skip``     templates (``URL``, ``FILE``, ``...`` without a line to repeat): nothing to run.

Lines run in their document's order in one working folder per document, a temporary folder
that holds a copy of ``tests/data``, the ``scripts`` and a ``docs/`` with only ``docs/api`` (as a checkout
does), so outputs go there and later lines find what earlier ones wrote; a line that reads a
file (``rerun``) runs after the others of its document. Each must exit 0 (or the exit code
in :data:`EXPECTED_EXIT`) within its time limit. Lines that still fail because of a default
being fixed elsewhere are listed in :data:`KNOWN_FAILING` (xfail, not strict, with the reason).
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import socket
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
DOCS = (REPO / "README.md", *sorted((REPO / "docs").glob("*.md")))
BIN = Path(sys.executable).parent
PROGRAMS = ("fdm-awe", "python", "rerun", "bash", "mavproxy.py")
_PROGRAM = re.compile(r"^(?:\.venv/bin/)?(fdm-awe|python|rerun|bash|mavproxy\.py)(?=\s|$)")

#: Stored references that stand for a documented optimisation in prose lines and scripts:
#: (scenario, config, wind m/s, line-drag factor, gamma bound rad or None) -> file in tests/data.
STORED_REFERENCES = {
    ("physical", "nominal", 8.0, 1.0, None): "ref_physical_nominal_8mps_sized.json",
    ("physical", "foldable", 8.0, 1.0, None): "ref_physical_foldable_8mps_sized.json",
    ("physical", "foldable", 8.0, 0.5, None): "ref_physical_foldable_8mps_halfline.json",
    ("paper", "nominal", 3.0, 1.0, 0.7): "ref_paper_nominal_3mps_gamma07.json",
    ("paper", "foldable", 3.0, 1.0, None): "ref_paper_foldable_3mps.json",
}
#: Options of ``fdm-awe fly`` that a reference fixes (refused together with ``--reference``).
REFERENCE_FIXED = ("--wind", "--wind-from", "--gamma-max", "--line", "--propeller", "--line-weight",
                   "--no-line-weight", "--generator")
#: of those, the options that take no value
REFERENCE_FIXED_FLAGS = ("--line-weight", "--no-line-weight")
#: Documented exit codes other than 0, by command line (none so far).
EXPECTED_EXIT: dict[str, int] = {}
#: Command lines that fail today because of a default another change is fixing:
#: command line -> reason. Each is run as xfail (not strict): flip it back once it passes.
KNOWN_FAILING: dict[str, str] = {}
#: Seconds one line may take (a 1-cycle flight with its optimisation takes about 25 s).
TIMEOUT_S = 240


@dataclass
class DocLine:
    """One documented command line: where it is and what it says."""

    doc: str  #: file relative to the repository
    lineno: int
    text: str  #: the command line, comment dropped, whitespace normalised
    block: int | None  #: index of its fenced code block (None: an inline code span)


@dataclass
class Plan:
    """What the test does with a documented line."""

    how: str  #: run | variant | parse | skip
    argv: list[str] = field(default_factory=list)
    changes: list[str] = field(default_factory=list)  #: what the variant changes, in words
    reason: str = ""  #: why parse or skip
    udp: bool = False  #: --mavlink redirected to the test's UDP socket (``{UDP_PORT}`` in argv)
    late: bool = False  #: runs after the other lines of its document (reads their outputs)

    def describe(self) -> str:
        if self.how == "variant":
            return "variant: " + "; ".join(self.changes)
        if self.how in ("parse", "skip"):
            return f"{self.how}: {self.reason}"
        return "run as written"


def _strip_comment(line: str) -> str:
    out, quote = [], None
    for i, ch in enumerate(line):
        if quote:
            quote = None if ch == quote else quote
        elif ch in "\"'":
            quote = ch
        elif ch == "#" and (i == 0 or line[i - 1].isspace()):
            break
        out.append(ch)
    return " ".join("".join(out).split())


def _is_whole_command(text: str) -> bool:
    """An inline code span names a command (``fdm-awe fly``) or gives a whole command line
    (an option or a file argument after the program)."""
    return any(t.startswith("--") or "/" in t or "." in t for t in shlex.split(text)[1:])


def documented_commands(docs: tuple[Path, ...] = DOCS, root: Path = REPO) -> list[DocLine]:
    """Every command line of ``docs`` (paths below ``root``) in document order: fenced code
    block lines and whole commands in inline code spans."""
    found: list[DocLine] = []
    for path in docs:
        rel = path.relative_to(root).as_posix()
        lines = path.read_text().splitlines()
        in_block, block, spans = False, -1, []
        for no, raw in enumerate(lines, 1):
            if raw.lstrip().startswith("```"):
                in_block = not in_block
                block += in_block
                continue
            if in_block:
                text = _strip_comment(raw.strip())
                if _PROGRAM.match(text):
                    found.append(DocLine(rel, no, text, block))
            else:
                spans.append((no, raw))
        # inline spans may wrap over a line break: join the prose, keep where each line starts
        prose, starts = "", []
        for no, raw in spans:
            starts.append((len(prose), no))
            prose += raw + "\n"
        for m in re.finditer(r"`([^`\n]+(?:\n[^`\n]+)?)`", prose):
            text = " ".join(m.group(1).split())
            if _PROGRAM.match(text) and _is_whole_command(text):
                no = max(n for pos, n in starts if pos <= m.start())
                found.append(DocLine(rel, no, text, None))
    order = [p.relative_to(root).as_posix() for p in docs]
    return sorted(found, key=lambda d: (order.index(d.doc), d.lineno))


def _expand(lines: list[DocLine]) -> list[DocLine]:
    """``PROG ... --more``: the previous full PROG line of the same block plus ``--more``
    (PROG is the program, for ``fdm-awe`` with its subcommand)."""
    out, last = [], {}
    for d in lines:
        words = d.text.split()
        cut = words.index("...") if "..." in words else len(words)
        prog = tuple(words[:2] if words[0].endswith("fdm-awe") and cut > 1 else words[:1])
        if cut < len(words) and d.block is not None and (d.doc, d.block, prog) in last:
            d = DocLine(d.doc, d.lineno, " ".join([last[(d.doc, d.block, prog)], *words[cut + 1:]]), d.block)
        elif cut == len(words):
            last[(d.doc, d.block, prog)] = d.text
        out.append(d)
    return out


def _value(argv: list[str], opt: str) -> str | None:
    for i, a in enumerate(argv):
        if a == opt and i + 1 < len(argv):
            return argv[i + 1]
        if a.startswith(opt + "="):
            return a.split("=", 1)[1]
    return None


def _drop(argv: list[str], opt: str, takes_value: bool = True, optional_value: bool = False) -> list[str]:
    out, skip = [], False
    for i, a in enumerate(argv):
        if skip:
            skip = False
            continue
        if a == opt:
            nxt = argv[i + 1] if i + 1 < len(argv) else None
            if takes_value and nxt is not None and (not optional_value or re.fullmatch(r"[0-9.]+", nxt)):
                skip = True
            continue
        if a.startswith(opt + "="):
            continue
        out.append(a)
    return out


def _set(argv: list[str], opt: str, value: str) -> list[str]:
    return _drop(argv, opt) + [opt, value]


def _stored_reference(argv: list[str], default_config: str) -> str | None:
    key = (_value(argv, "--scenario") or "physical", _value(argv, "--config") or default_config,
           float(_value(argv, "--wind") or 8.0), float(_value(argv, "--tether-drag-scale") or 1.0),
           None if _value(argv, "--gamma-max") is None else float(_value(argv, "--gamma-max")))
    name = STORED_REFERENCES.get(key)
    # the stored references fly the scenario's default plant: another line or generator optimises
    scenario_line = "sized" if key[0] == "physical" else "paper"
    if _value(argv, "--line") not in (None, scenario_line) or _value(argv, "--generator") not in (None, "passive"):
        return None
    return None if name is None else f"tests/data/{name}"


def plan(d: DocLine) -> Plan:
    """The plan for one documented line (see the module docstring)."""
    words = shlex.split(d.text)
    prog = _PROGRAM.match(d.text).group(1)
    args = words[1:]
    if "..." in args or any(a in ("URL", "FILE", "DIR") for a in args):
        return Plan("skip", reason="a template, not a command line")
    if prog == "bash":
        return Plan("parse", ["bash", "-n", *args[:1]],
                    reason=f"bash -n {args[0]}: it installs packages or runs this test suite")
    if prog == "mavproxy.py":
        return Plan("parse", [str(BIN / "mavproxy.py"), "--help"],
                    reason="mavproxy.py --help: MAVProxy is another program, a ground station that waits for a vehicle")
    if prog == "rerun":
        if args and args[0] == "rrd":
            return Plan("run", [str(BIN / "rerun"), *args], late=True)
        return Plan("variant", [str(BIN / "rerun"), "rrd", "verify", *args], late=True,
                    changes=["rerun rrd verify FILE instead of the viewer (needs a display)"])
    if prog == "python":
        script = args[0]
        if Path(script).name.startswith("bench_"):
            return Plan("parse", [sys.executable, script, "--help"],
                        reason="--help: a benchmark, its verdict depends on the machine (run it on a quiet one)")
        argv, changes = [sys.executable, *args], []
        if Path(script).name == "fly_one_cycle.py" and "--reference" not in args:
            ref = _stored_reference(args, "foldable")
            if ref:
                argv += ["--reference", ref]
                changes.append(f"--reference {ref} (the stored reference of this case) instead of optimising")
        if Path(script).name == "compare_tether.py":
            for opt, val in (("--cycles", "1"), ("--models", "straight,lumped:10")):
                if _value(argv, opt) != val:
                    argv = _set(argv, opt, val)
                    changes.append(f"{opt} {val}")
        if Path(script).name == "wind_grid.py":
            for opt, val in (("--refs", "tests/data/ref_physical_nominal_8mps_sized.json"), ("--air", "calm,light"),
                             ("--seeds", "1"), ("--cycles", "1"), ("--workers", "1")):
                if _value(argv, opt) != val:
                    argv = _set(argv, opt, val)
                    changes.append(f"{opt} {val}")
        if Path(script).name == "drive_map.py":  # two supplies, one foldable span and wind, coarse, on the grid alone
            for opt, val in (("--supply-voltage", "24,48"), ("--folded-span", "0.22"), ("--wind", "10"),
                             ("--mesh", "12,8,3"), ("--codesign-steps", "0"), ("--workers", "1")):
                if _value(argv, opt) != val:
                    argv = _set(argv, opt, val)
                    changes.append(f"{opt} {val}")
            if "--no-cold-check" not in argv:
                argv.append("--no-cold-check")
                changes.append("--no-cold-check")
        if Path(script).name == "line_calibration.py":  # one point, one cycle
            for opt, val in (("--winds", "10"), ("--configs", "nominal"), ("--cycles", "1")):
                if _value(argv, opt) != val:
                    argv = _set(argv, opt, val)
                    changes.append(f"{opt} {val}")
        if Path(script).name == "reproduce_table3.py" and "--no-zero-wind" not in args:
            argv.append("--no-zero-wind")
            changes.append("--no-zero-wind (the zero-wind check runs in the compare line of the README)")
        return Plan("variant" if changes else "run", argv, changes)
    # fdm-awe
    argv, changes = [str(BIN / "fdm-awe"), *args], []
    cmd = args[0] if args else ""
    if cmd == "sweep" and _value(args, "--scheduler"):
        return Plan("parse", argv, reason="the command line's parser: --scheduler needs an outside Dask cluster")
    plan_ = Plan("run", argv)
    if cmd == "fly":
        inline = d.block is None
        if inline and "--reference" not in args:
            ref = _stored_reference(args, "nominal")
            if ref:
                argv = _without_reference_fixed(argv) + ["--reference", ref]
                changes.append(f"--reference {ref} (the stored reference of this case) instead of optimising")
        if _value(argv, "--cycles") != "1":
            argv = _set(argv, "--cycles", "1")
            changes.append("--cycles 1")
        if "--realtime" in argv or any(a.startswith("--realtime=") for a in argv):
            argv = _set(_drop(argv, "--realtime", optional_value=True), "--realtime", "100")
            changes.append("--realtime 100 (a cycle in 0.6 s)")
        if "--mavlink" in argv:
            argv = [re.sub(r":\d+$", ":{UDP_PORT}", a) if a.startswith(("udpout:", "udp:")) else a for a in argv]
            plan_.udp = True
            changes.append("--mavlink to a UDP socket of the test on 127.0.0.1 (it must receive MAVLink 2 frames)")
    if cmd in ("optimize", "compare") and _value(args, "--mesh") is None:
        argv = _set(argv, "--mesh", "20,10,3")
        changes.append("--mesh 20,10,3")
    if cmd == "sweep":
        if _value(args, "--wind") not in (None, "8"):
            argv = _set(argv, "--wind", "8")
            changes.append("--wind 8")
        if _value(args, "--config") not in (None, "nominal"):
            argv = _set(argv, "--config", "nominal")
            changes.append("--config nominal (a foldable point uses its whole iteration budget)")
        for opt in ("--folded-span", "--folded-drag-area"):
            if _value(args, opt) is not None:
                argv = _drop(argv, opt)
                changes.append(f"no {opt} (nominal points only)")
        if _value(args, "--workers") not in (None, "1"):
            argv = _set(argv, "--workers", "1")
            changes.append("--workers 1")
        if _value(args, "--mesh") is None:
            argv = _set(argv, "--mesh", "10,8,3")
            changes.append("--mesh 10,8,3")
        if _value(args, "--config") is None:
            argv = _set(argv, "--config", "nominal")
            changes.append("--config nominal")
        if "--fly" in args:  # one short flight per point
            for opt in ("--fly-seeds", "--fly-cycles"):
                if _value(args, opt) != "1":
                    argv = _set(argv, opt, "1")
                    changes.append(f"{opt} 1")
    plan_.argv = argv
    if changes:
        plan_.how, plan_.changes = "variant", changes
    return plan_


def _without_reference_fixed(argv: list[str]) -> list[str]:
    for opt in REFERENCE_FIXED:
        argv = _drop(argv, opt, takes_value=opt not in REFERENCE_FIXED_FLAGS)
    return argv


def plans(lines: list[DocLine]) -> list[Plan]:
    """:func:`plan` of each line; a line repeated word for word runs once, where it first appears."""
    out, first = [], {}
    for d in lines:
        if d.text in first:
            out.append(Plan("skip", reason=f"the same line as {first[d.text]} (run there)"))
        else:
            first[d.text] = f"{d.doc}:{d.lineno}"
            out.append(plan(d))
    return out


LINES = _expand(documented_commands())
PLANS = plans(LINES)


def _param(d: DocLine, p: Plan):
    marks = []
    if d.text in KNOWN_FAILING:
        marks.append(pytest.mark.xfail(reason=KNOWN_FAILING[d.text], strict=False))
    return pytest.param(d, p, id=f"{d.doc}:{d.lineno} {p.how}", marks=marks)


# Document order, a document's late lines (they read earlier outputs) after its others.
ORDERED = sorted(zip(LINES, PLANS), key=lambda dp: (DOCS.index(REPO / dp[0].doc), dp[1].late, dp[0].lineno))


@pytest.fixture(scope="module")
def workspaces(tmp_path_factory):
    """One working folder per document, laid out like a checkout's top level."""
    made: dict[str, Path] = {}

    def get(doc: str) -> Path:
        if doc not in made:
            ws = tmp_path_factory.mktemp(Path(doc).stem)
            shutil.copytree(REPO / "tests" / "data", ws / "tests" / "data")
            (ws / "scripts").symlink_to(REPO / "scripts", target_is_directory=True)
            (ws / "docs").mkdir()
            (ws / "docs" / "api").symlink_to(REPO / "docs" / "api", target_is_directory=True)  # sphinx's source
            made[doc] = ws
        return made[doc]

    return get


def test_plan_table():
    """Every documented command line has a plan; the table says which ran and how."""
    table = [f"{d.doc}:{d.lineno}: {d.text}\n    -> {p.describe()}" for d, p in ORDERED]
    print("\n".join(table))
    assert len(LINES) >= 20, "the extraction finds the documented commands"
    docs_with_lines = {d.doc for d in LINES}
    assert {"README.md", "docs/mavlink.md", "docs/recordings.md", "docs/sweep.md"} <= docs_with_lines
    assert sum(p.how in ("run", "variant") for p in PLANS) >= 15
    for d, p in zip(LINES, PLANS):
        assert p.how in ("run", "variant", "parse", "skip"), d
        assert p.how != "skip" or "same line" in p.reason or d.block is None or "..." in d.text, \
            f"{d.doc}:{d.lineno} a code-block line is not run"


def test_the_default_flight_is_documented_and_run_as_written():
    """``fdm-awe fly`` with no options is a documented line, flown as written but for one cycle."""
    fly = [(d, p) for d, p in zip(LINES, PLANS) if shlex.split(d.text)[1:] == ["fly"]]
    assert fly, "README documents the plain 'fdm-awe fly'"
    assert all(p.changes == ["--cycles 1"] for _, p in fly)


def test_extraction_finds_block_lines_inline_commands_and_repeats(tmp_path):
    md = tmp_path / "x.md"
    md.write_text("text `fdm-awe fly` and `fdm-awe fly --cycles 2`\n"
                  "```\nfdm-awe sweep --wind 3 --out runs/s   # comment\nfdm-awe sweep ... --scenario paper\n"
                  "mavproxy.py --master=udpin:127.0.0.1:1\n```\n"
                  "`python scripts/x.py --out\nruns/y` and `rerun run.rrd`\n")
    lines = [d.text for d in _expand(documented_commands((md,), tmp_path))]
    assert lines == ["fdm-awe fly --cycles 2", "fdm-awe sweep --wind 3 --out runs/s",
                     "fdm-awe sweep --wind 3 --out runs/s --scenario paper", "mavproxy.py --master=udpin:127.0.0.1:1",
                     "python scripts/x.py --out runs/y", "rerun run.rrd"]


def _mavlink2_frames(sock: socket.socket) -> int:
    n = 0
    sock.setblocking(False)
    while True:
        try:
            data = sock.recv(65536)
        except BlockingIOError:
            return n
        n += data[:1] == b"\xfd"


@pytest.mark.timeout(TIMEOUT_S + 30)
@pytest.mark.parametrize("d,p", [_param(d, p) for d, p in ORDERED])
def test_documented_command_runs(d: DocLine, p: Plan, workspaces):
    if p.how == "skip":
        pytest.skip(p.reason)
    ws = workspaces(d.doc)
    argv, sock = list(p.argv), None
    if p.udp:
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.bind(("127.0.0.1", 0))
        argv = [a.replace("{UDP_PORT}", str(sock.getsockname()[1])) for a in argv]
    if p.how == "parse" and argv[0].endswith("fdm-awe"):
        from fdm_awe.cli import build_parser

        build_parser().parse_args(argv[1:])  # exits 2 on an option the command does not know
        return
    env = {**os.environ, "JSBSIM_DEBUG": "0", "MPLBACKEND": "Agg"}
    try:
        proc = subprocess.run(argv, cwd=ws, env=env, capture_output=True, text=True, errors="replace",
                              timeout=TIMEOUT_S)
        want = EXPECTED_EXIT.get(d.text, 0)
        tail = "\n".join((proc.stdout + proc.stderr).strip().splitlines()[-15:])
        assert proc.returncode == want, f"{d.doc}:{d.lineno}: {' '.join(argv)} exited {proc.returncode}\n{tail}"
        if sock is not None:
            assert _mavlink2_frames(sock) > 0, "no MAVLink 2 frame reached the ground-station socket"
    finally:
        if sock is not None:
            sock.close()


def _tracked_text_files() -> list[Path]:
    """The repository's text files (git's list in a checkout, else every file outside build
    outputs and environments), without the stored trajectories."""
    if (REPO / ".git").exists() and shutil.which("git"):
        out = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=REPO,
                             capture_output=True, check=True).stdout.decode()
        paths = [REPO / p for p in out.split("\0") if p]
    else:
        skip = {".git", ".venv", "build", "dist", "runs", "__pycache__"}
        paths = [p for p in REPO.rglob("*") if not skip & set(p.relative_to(REPO).parts)]
    files = []
    for p in paths:
        if p.is_file() and "tests/data" not in p.relative_to(REPO).as_posix() and p.suffix not in (".png", ".rrd", ".npz"):
            try:
                p.read_text()
            except UnicodeDecodeError:
                continue
            files.append(p)
    return files


def test_no_file_refers_to_a_document_outside_the_repository():
    """Every ``folder/name.md`` a file mentions exists in the repository, and nothing cites the
    design notes under another name than docs/design.md."""
    bad = []
    for p in _tracked_text_files():
        if p == Path(__file__).resolve():
            continue  # the patterns below
        text = p.read_text()
        rel = p.relative_to(REPO).as_posix()
        if re.search(r"\bDESIGN\.md\b", text):
            bad.append(f"{rel}: DESIGN.md")
        for m in re.finditer(r"(?<![\w./-])((?:\.\./|[A-Za-z0-9_-]+/)+[A-Za-z0-9_.-]+\.md)\b", text):
            target = m.group(1)
            if not ((REPO / target).is_file() or (p.parent / target).is_file() or target.startswith(("out/", "runs/"))):
                bad.append(f"{rel}: {target}")
    assert not bad, "references to documents that are not in the repository: " + "; ".join(sorted(set(bad)))


def _design_sections() -> set[str]:
    text = (REPO / "docs" / "design.md").read_text()
    return {m.group(1) for m in re.finditer(r"^#{2,3} (\d+[a-z]?(?:\.\d+)?)\.? ", text, re.M)}


def test_every_cited_section_of_the_design_document_exists():
    sections = _design_sections()
    assert {"1", "2", "3", "4", "5", "6", "7", "8", "8b", "9", "4.3", "4.5", "4.8"} <= sections
    cite = re.compile(r"docs/design\.md(?:'s)?\s*(?:sections?\s+)?((?:\d+[a-z]?(?:\.\d+)?)(?:(?:,\s*|\s+and\s+)\d+[a-z]?(?:\.\d+)?)*)")
    missing = []
    for p in _tracked_text_files():
        for m in cite.finditer(p.read_text()):
            for n in re.findall(r"\d+[a-z]?(?:\.\d+)?", m.group(1)):
                if n not in sections:
                    missing.append(f"{p.relative_to(REPO).as_posix()}: section {n}")
    assert not missing, "cited sections missing from docs/design.md: " + "; ".join(sorted(set(missing)))
