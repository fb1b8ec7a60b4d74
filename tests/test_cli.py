"""CLI shell: in-process entry point, help, exit codes for user errors."""

import subprocess
import sys

from tactileskin.cli import main


def test_help_lists_commands(capsys):
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    for cmd in ("sweep",):
        assert cmd in out


def test_unknown_command_is_a_usage_error(capsys):
    assert main(["frobnicate"]) == 2


def test_user_error_is_one_line_without_traceback(capsys, tmp_path):
    rc = main(["sweep", "--thickness", "9", "--out", str(tmp_path / "o"), "--serial"])
    err = capsys.readouterr().err
    assert rc == 2
    assert "thickness" in err and "[0.5, 5.512]" in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()  # nothing written for a rejected request


def test_module_entry_point():
    r = subprocess.run([sys.executable, "-m", "tactileskin", "--version"], capture_output=True, text=True)
    assert r.returncode == 0 and "version" in r.stdout
