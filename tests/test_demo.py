from gymfg_il import demo


def test_demo_flies_and_prints_a_table(capsys):
    assert demo.main(["--episodes", "1", "--episode-time", "30"]) == 0
    out = capsys.readouterr().out
    assert "altitude task, c172p" in out and "time limit" in out
