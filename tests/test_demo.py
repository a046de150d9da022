import json
import shutil
import subprocess
from pathlib import Path

import pytest

from gymfg_il import demo

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_main_job_runs_the_whole_loop_and_writes_a_report(tmp_path, capsys):
    code = demo.main(
        [
            "--epochs",
            "3",
            "--episodes",
            "2",
            "--workers",
            "1",
            "--runs",
            str(tmp_path),
            "--no-progress",
        ]
    )
    assert code == 0
    out = capsys.readouterr().out
    run = next(tmp_path.iterdir())
    assert f"report: {run / 'report.md'}" in out
    assert "policy:bc-mlp / controller: return" in out  # #53: the share, not the table alone
    report = (run / "report.md").read_text()
    assert "policy:bc-mlp / controller: return" in report and "![loss](loss.png)" in report
    rows = json.loads((run / "eval.json").read_text())["rows"]
    assert [r["agent"] for r in rows] == ["controller", "policy:bc-mlp"]  # not policy:policy
    assert rows[0]["seeds"] == [0, 1]  # held out: the bundled demonstrations use 1000+
    assert (run / "plots" / "altitude_c172p_policy-bc-mlp.png").is_file()
    assert (run / "bc-mlp" / "model.safetensors").is_file()


def test_outside_the_checkout_the_demo_says_what_to_do_and_leaves_nothing(
    tmp_path, monkeypatch, capsys
):
    monkeypatch.chdir(tmp_path)  # no bundled sample here, and no recipe to collect it
    assert demo.main(["--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "no recipe at collectors/sample.toml" in err and "--dataset DIR" in err
    assert list(tmp_path.iterdir()) == []  # no empty runs/<time>/


@pytest.mark.skipif(
    shutil.which("git") is None or not (ROOT / ".git").exists(), reason="not a git checkout"
)
def test_what_commands_write_by_default_is_ignored_by_git():
    written = [
        "datasets/autopilot/dataset/meta/info.json",  # collect autopilot
        "datasets/manual/logs/manual.mcap",  # collect manual
        "datasets/sample-altitude-c172p-remade/dataset/README.md",  # the sample's recipe
        "datasets/sample-altitude-c172p/logs/autopilot.mcap",  # the bundled sample's logs
        "policies/bc-altitude-c172p-mlp/config.json",  # train bc
        "runs/20260101-000000/report.md",  # demo
    ]
    bundled = "datasets/sample-altitude-c172p/dataset/README.md"
    done = subprocess.run(
        ["git", "check-ignore", "--no-index", *written, bundled],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert done.stdout.split() == written  # all but the bundled sample
