import json
import subprocess
import sys

from gymfg_il import eval as evaluate


def test_eval_flies_the_controller_and_writes_json_and_figure1(tmp_path, capsys):
    code = evaluate.main(
        [
            "--task",
            "roll",
            "--aircraft",
            "f15",
            "--episodes",
            "2",
            "--episode-time",
            "30",
            "--json",
            str(tmp_path / "rows.json"),
            "--plots",
            str(tmp_path / "plots"),
            "--no-progress",
        ]
    )
    assert code == 0
    out = capsys.readouterr().out
    assert "controller" in out and "success" in out
    rows = json.loads((tmp_path / "rows.json").read_text())["rows"]
    assert len(rows) == 1
    row = rows[0]
    assert (row["agent"], row["task"], row["aircraft"]) == ("controller", "roll", "f15")
    assert row["episodes"] == 2 and row["seeds"] == [0, 1]
    assert row["success_rate"] == 1.0 and row["steady_state_error"] < 2
    png = tmp_path / "plots" / "roll_f15_controller.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000


def test_same_seeds_give_the_same_rows(tmp_path):
    args = [
        "--task",
        "heading",
        "--dynamic",
        "--episodes",
        "2",
        "--episode-time",
        "20",
        "--no-progress",
        "--json",
    ]
    evaluate.main([*args, str(tmp_path / "a.json")])
    evaluate.main([*args, str(tmp_path / "b.json")])
    assert (tmp_path / "a.json").read_text() == (tmp_path / "b.json").read_text()


def test_bad_aircraft_is_a_clear_error(capsys):
    assert evaluate.main(["--aircraft", "c172q", "--no-progress"]) == 2
    assert "c172p" in capsys.readouterr().err


def test_help_explains_every_option():
    out = subprocess.run(
        [sys.executable, "-m", "gymfg_il.eval", "--help"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    for option in (
        "--task",
        "--dynamic",
        "--aircraft",
        "--episodes",
        "--seed",
        "--json",
        "--plots",
    ):
        assert option in out
    assert "Figure 1" in out
