import json

from gymfg_il import demo


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
    report = (run / "report.md").read_text()
    assert "policy:policy / controller: return" in report and "![loss](loss.png)" in report
    rows = json.loads((run / "eval.json").read_text())["rows"]
    assert [r["agent"] for r in rows] == ["controller", "policy:policy"]
    assert rows[0]["seeds"] == [0, 1]  # held out: the bundled demonstrations use 1000+
    assert (run / "plots" / "altitude_c172p_policy-policy.png").is_file()
    assert (run / "policy" / "model.safetensors").is_file()
