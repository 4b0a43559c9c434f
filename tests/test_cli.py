"""The command line: help lists the commands, errors exit non-zero with one line."""

import subprocess
import sys

from fdm_awe.cli import COMMANDS, main


def test_help_lists_existing_commands():
    out = subprocess.run([sys.executable, "-m", "fdm_awe", "--help"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0
    for name in COMMANDS:
        assert name in out.stdout


def test_no_command_prints_help_and_fails(capsys):
    assert main([]) == 2


def test_info_runs(tmp_path, capsys):
    assert main(["info", "--json", str(tmp_path / "i.json")]) == 0
    assert "best glide" in capsys.readouterr().out
    assert (tmp_path / "i.json").stat().st_size > 0
