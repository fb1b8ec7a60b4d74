"""The CLI's errors name the option the user typed, and a near miss of a fixed choice gets the
project's "did you mean" (validate.did_you_mean) as a misspelt material or indenter name does:
`sweep --braille-dim both` under force control was refused naming `braille_dims=[2, 3]` (the
API's name), and `film analyze --rows center`, `array --set letter`, `solve --dim 4`-like choice
slips had no suggestion."""

from __future__ import annotations

import pytest

from tactileskin.cli import main
from tactileskin.errors import ParameterError


def _err(capsys) -> str:
    cap = capsys.readouterr()
    assert "Traceback" not in cap.err + cap.out
    return " ".join(cap.err.split())


def test_force_control_with_both_braille_dims_names_the_option_typed(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["sweep", "-i", "braille", "--braille-dim", "both", "--force", "1", "-t", "1", "-m", "silicone",
                 "--serial", "--out", str(out)]) == 2
    err = _err(capsys)
    assert "--braille-dim='both' is invalid" in err and "one dimension under force control" in err, err
    assert "braille_dims" not in err and not out.exists()
    # the API keeps its own name
    from tactileskin.sweep import expand_grid

    with pytest.raises(ParameterError, match=r"braille_dims=\[2, 3\]"):
        expand_grid(indenters=("braille",), braille_dims=(2, 3), forces=(1.0,))


def test_a_file_s_braille_dims_under_force_control_names_the_file_s_key(tmp_path, capsys):
    f = tmp_path / "s.toml"
    f.write_text('[scene]\nforce = 1.0\n[sweep]\nindenters = ["braille"]\nbraille_dims = [2, 3]\nthicknesses = [1.0]\n')
    assert main(["sweep", "--scene", str(f), "--serial", "--out", str(tmp_path / "out")]) == 2
    err = _err(capsys)
    assert "sweep.braille_dims=[2, 3] is invalid" in err, err


@pytest.mark.parametrize("argv, suggestion", [
    (["film", "analyze", "SCAN", "--calibration", "CAL", "--px-per-mm", "10", "--rows", "center", "-o", "OUT"],
     "did you mean 'centre'?"),
    (["array", "--set", "letter", "-o", "OUT"], "did you mean 'letters'?"),
    (["solve", "-i", "sphre", "-o", "OUT"], "did you mean 'sphere'?"),
])
def test_a_near_miss_of_a_choice_gets_a_did_you_mean(tmp_path, capsys, argv, suggestion):
    scan, cal = tmp_path / "scan.png", tmp_path / "cal.toml"
    scan.write_bytes(b"")
    cal.write_text("")
    argv = [{"SCAN": str(scan), "CAL": str(cal), "OUT": str(tmp_path / "out")}.get(a, a) for a in argv]
    assert main(argv) == 2
    err = _err(capsys)
    assert suggestion in err, err
    assert not (tmp_path / "out").exists()
