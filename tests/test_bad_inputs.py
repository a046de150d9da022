"""Bad input to the command lines gets one clear line and exit status 2, never a traceback
(red-team findings: each case below raised a traceback before)."""

import os
import shutil
import socket
from pathlib import Path

import pytest

from gymfg_il import collect, serve, train
from gymfg_il import eval as evaluate

SAMPLE = Path(__file__).resolve().parents[1] / "datasets/sample-altitude-c172p/dataset"


def one_error(capsys, *needles):
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.startswith("error: "), err
    for needle in needles:
        assert needle in err, err


@pytest.mark.parametrize(
    "line, needle",
    [
        ('task_kwargs = "x"', "task_kwargs='x': want dict"),
        ("out = 5", "out=5: want Path"),
        ('dynamic = "no"', "dynamic='no': want bool"),
        ('episodes = "3"', "episodes='3': want int"),
    ],
)
def test_recipe_values_of_the_wrong_type(tmp_path, capsys, line, needle):
    recipe = tmp_path / "r.toml"
    recipe.write_text(f"[collector]\n{line}\n")
    assert collect.main([str(recipe), "--no-progress"]) == 2
    one_error(capsys, needle)


def test_collect_out_where_nothing_can_be_written(tmp_path, capsys):
    (tmp_path / "a-file").write_text("")
    argv = ["autopilot", "--out", str(tmp_path / "a-file" / "x"), "--episodes", "1"]
    assert collect.main([*argv, "--no-progress"]) == 2
    one_error(capsys, "cannot write there")


def damaged(tmp_path, how):
    root = tmp_path / "dataset"
    shutil.copytree(SAMPLE, root)
    how(root)
    return root


def truncate(path):
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 3])


@pytest.mark.parametrize(
    "how, needle",
    [
        (lambda r: truncate(next((r / "data").rglob("*.parquet"))), "not readable parquet"),
        (lambda r: next((r / "data").rglob("*.parquet")).unlink(), "no data files"),
        (lambda r: (r / "meta" / "tasks.parquet").unlink(), "tasks.parquet is missing"),
        (lambda r: (r / "meta" / "info.json").write_text("{garbled"), "info.json is not valid"),
        (lambda r: (r / "meta" / "stats.json").write_text("{garbled"), "stats.json is not valid"),
        (lambda r: (r / "meta" / "stats.json").unlink(), "stats.json is missing"),
    ],
)
def test_train_on_an_incomplete_dataset_says_what_is_missing(tmp_path, capsys, how, needle):
    root = damaged(tmp_path, how)
    argv = ["bc", "--dataset", str(root), "--epochs", "1", "--out", str(tmp_path / "p")]
    assert train.main([*argv, "--no-progress"]) == 2
    one_error(capsys, "is incomplete", needle)


def test_train_refuses_a_bad_out_and_nan_before_training(tmp_path, capsys):
    (tmp_path / "a-file").write_text("")
    base = ["bc", "--dataset", str(SAMPLE), "--epochs", "1", "--no-progress"]
    assert train.main([*base, "--out", str(tmp_path / "a-file")]) == 2
    one_error(capsys, "is a file")
    assert train.main([*base, "--weight-decay", "nan", "--out", str(tmp_path / "p")]) == 2
    one_error(capsys, "weight_decay=nan")
    assert not (tmp_path / "p").exists()


def test_train_takes_a_session_folder_for_its_dataset(tmp_path):
    session = tmp_path / "session"
    shutil.copytree(SAMPLE, session / "dataset")
    argv = ["bc", "--dataset", str(session), "--epochs", "1", "--out", str(tmp_path / "p")]
    assert train.main([*argv, "--no-progress"]) == 0


def resize(config):
    """The config of another network than the weights hold."""
    text = config.read_text()
    config.write_text(text.replace('"hidden": [\n      32', '"hidden": [\n      64'))


@pytest.fixture(scope="module")
def policy(tmp_path_factory):
    out = tmp_path_factory.mktemp("policy")
    argv = ["bc", "--dataset", str(SAMPLE), "--epochs", "1", "--hidden", "32", "--out", str(out)]
    assert train.main([*argv, "--no-progress"]) == 0
    return out


@pytest.mark.parametrize(
    "damage, needle",
    [
        (lambda p: (p / "config.json").write_text("{garbled"), "is not valid JSON"),
        (lambda p: (p / "config.json").write_text(""), "is not valid JSON"),
        (lambda p: (p / "model.safetensors").write_bytes(b"garbage"), "cannot be loaded"),
        (lambda p: truncate(p / "model.safetensors"), "cannot be loaded"),
        (
            lambda p: (p / "config.json").write_text(
                (p / "config.json")
                .read_text()
                .replace('"hidden": [\n      32', '"hidden": [\n      64')
            ),
            "does not match",
        ),
    ],
)
def test_eval_checks_a_policy_before_anything_flies(policy, tmp_path, capsys, damage, needle):
    broken = tmp_path / "broken"
    shutil.copytree(policy, broken)
    damage(broken)
    assert evaluate.main(["--policy", str(broken), "--episodes", "1", "--no-progress"]) == 2
    one_error(capsys, needle)


@pytest.mark.parametrize("task", ["sys:modules", "os:environ"])
def test_a_record_naming_a_module_attribute_as_its_task_is_one_short_line(
    policy, tmp_path, capsys, task
):
    """#52.12: a policy whose flight spec names ``sys:modules`` as its task printed all of
    ``sys.modules`` (``os:environ``: the environment, secrets and all) in its error."""
    import json

    named = tmp_path / "named"
    shutil.copytree(policy, named)
    config = json.loads((named / "config.json").read_text())
    config["spec"]["teams"][0]["roster"][0]["task"] = task
    (named / "config.json").write_text(json.dumps(config))
    assert evaluate.main(["--policy", str(named), "--episodes", "1", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "Traceback" not in err, err[:500]
    kind = "dict" if task == "sys:modules" else "_Environ"
    assert f"{task!r} is a {kind}, not a Task class" in err, err[:500]
    assert len(err) < 300, err[:500]


def test_serve_and_replay_refuse_impossible_ports_and_addresses(capsys):
    for argv in (
        ["--port", "99999"],
        ["--port", "-1"],
        ["--bind", "10.255.255.1", "--secret", "x"],
    ):
        assert serve.main(argv) == 2
        one_error(capsys)
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        assert serve.main(["--port", str(taken.getsockname()[1])]) == 2
        one_error(capsys, "cannot listen")
    assert collect.main(["replay", "nowhere", "--view", "99999"]) == 2
    one_error(capsys, "--view 99999")


def test_a_zero_share_is_not_a_nan_percent():
    from gymfg_il.evaluation.report import ratio_line

    row = {"agent": "policy:p", "return_ratio": 0.5, "success_ratio": None}
    assert (
        ratio_line(row)
        == "policy:p / controller: return 50.0%, success n/a (the controller's is 0)"
    )


def test_eval_json_where_no_folder_can_be_is_refused_before_flying(tmp_path, capsys):
    (tmp_path / "a-file").write_text("")
    for flag in ("--json", "--plots"):
        where = tmp_path / "a-file" / "sub" / ("r.json" if flag == "--json" else "plots")
        argv = [flag, str(where), "--episodes", "1", "--episode-time", "1", "--no-progress"]
        assert evaluate.main(argv) == 2
        one_error(capsys, f"{flag} {where}", "is a file")


SEED_RULE = "0 <= seed < 2**32"


@pytest.mark.parametrize("seed", ["-1", str(2**32), str(2**64), str(2**70)])
def test_every_commands_seed_is_checked_once(tmp_path, capsys, seed):
    out = str(tmp_path / "out")
    assert collect.main(["autopilot", "--seed", seed, "--out", out, "--no-progress"]) == 2
    one_error(capsys, f"seed={seed}", SEED_RULE)
    assert evaluate.main(["--seed", seed, "--episodes", "1", "--no-progress"]) == 2
    one_error(capsys, f"seed={seed}", SEED_RULE)
    argv = ["bc", "--dataset", str(SAMPLE), "--seed", seed, "--out", out, "--no-progress"]
    assert train.main(argv) == 2
    one_error(capsys, f"seed={seed}", SEED_RULE)
    argv = ["dagger", "--policy", str(tmp_path / "p"), "--out", out, "--seed", seed]
    assert collect.main(argv) == 2
    one_error(capsys, f"seed={seed}", SEED_RULE)
    recipe = tmp_path / "r.toml"
    recipe.write_text(f"[collector]\nseed = {seed}\n")
    assert collect.main([str(recipe), "--no-progress"]) == 2
    one_error(capsys, f"seed={seed}", SEED_RULE)
    assert not (tmp_path / "out").exists()


def test_the_last_episodes_seed_is_a_seed_too(tmp_path, capsys):
    argv = ["--seed", str(2**32 - 2), "--episodes", "3", "--no-progress"]
    assert evaluate.main(argv) == 2
    one_error(capsys, "episode 2 has seed 4294967296", SEED_RULE)


@pytest.mark.parametrize("time", ["1e308", "inf", "nan", "1e300"])
def test_an_endless_episode_time_is_refused(tmp_path, capsys, time):
    assert evaluate.main(["--episode-time", time, "--episodes", "1", "--no-progress"]) == 2
    one_error(capsys, "episode_time_s=")
    argv = ["autopilot", "--episode-time", time, "--out", str(tmp_path / "o"), "--no-progress"]
    assert collect.main(argv) == 2
    one_error(capsys, "episode_time_s=")


@pytest.mark.parametrize(
    "name", ["../../x-v0", "../x-v0", "a/../../x-v0", "/abs/x-v0", ".hidden-v0", "a\nb-v0"]
)
def test_a_minari_id_never_leaves_its_root(tmp_path, capsys, name):
    root = tmp_path / "a" / "b" / "root"
    root.mkdir(parents=True)
    argv = ["export", "minari", str(SAMPLE), "--name", name, "--root", str(root)]
    assert collect.main(argv) == 2
    one_error(capsys, "--name", "Minari dataset id")
    assert sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*")) == [
        Path("a"), Path("a/b"), Path("a/b/root")
    ]  # fmt: skip


BAD_NAMES = ["red\nINFO forged line", "\x1b[31mred", "nul\x00", "\u202eder", "x" * 65, "zero\u200b"]


@pytest.mark.parametrize("bad", BAD_NAMES)
def test_callsigns_and_team_names_are_printable_and_short(bad):
    from gymfg_il.aircraft import c172p
    from gymfg_il.envs.team import Team
    from gymfg_il.errors import ConfigError
    from gymfg_il.names import RULE
    from gymfg_il.tasks.library import DummyTask

    with pytest.raises(ConfigError, match="callsign") as err:
        c172p(bad)
    assert RULE in str(err.value) and "\n" not in str(err.value)
    with pytest.raises(ConfigError, match="team") as err:
        Team(name=bad, roster=[(c172p("one"), DummyTask)])
    assert RULE in str(err.value)
    assert Team(name="red one", roster=[(c172p("x" * 64), DummyTask)]).callsigns == ["x" * 64]


def test_acmi_out_where_nothing_can_be_written(tmp_path, capsys):
    argv = ["autopilot", "--episodes", "1", "--episode-time", "1", "--out", str(tmp_path / "s")]
    assert collect.main([*argv, "--no-progress"]) == 0
    (tmp_path / "a-file").write_text("")
    out = tmp_path / "a-file" / "x.acmi"
    assert collect.main(["export", "acmi", str(tmp_path / "s"), "--out", str(out)]) == 2
    one_error(capsys, f"--out {out}: cannot write there")


def test_a_reader_that_goes_away_ends_the_command_quietly():
    """``collect recover DIR | head -1`` ended in a BrokenPipeError traceback."""
    import subprocess
    import sys

    code = (
        "import sys; from gymfg_il import cli; "
        "sys.exit(cli.run(lambda: [print('line', i) for i in range(200000)] and 0))"
    )
    shell = f'{sys.executable} -c "{code}" | head -1'
    done = subprocess.run(["bash", "-c", shell], capture_output=True, text=True, timeout=300)
    assert done.stdout == "line 0\n"
    assert "Traceback" not in done.stderr and "Exception ignored" not in done.stderr, done.stderr


def test_recover_refuses_a_callsign_off_the_name_rule(tmp_path, capsys):
    assert collect.main(["recover", str(tmp_path), "--callsign", "a\nb"]) == 2
    one_error(capsys, "printable")


@pytest.mark.parametrize("name", [" ", " ann", "ann ", "a|b", "ann\nbob", ""])
def test_a_pilot_name_that_would_break_a_table_is_refused(tmp_path, capsys, name):
    """#52.4: --pilot-name let '|' (which breaks the card's table) and a lone space through."""
    assert collect.main(["manual", "--pilot-name", name, "--out", str(tmp_path / "s")]) == 2
    one_error(capsys, "pilot name")
    assert not (tmp_path / "s").exists()


def test_a_progress_bar_into_a_log_is_lines_not_redraws(tmp_path):
    """#53: progress bars redrew themselves ("\\r") into logs when stderr was a file."""
    import subprocess
    import sys

    argv = ["autopilot", "--task", "roll", "--episodes", "3", "--episode-time", "4"]
    with open(tmp_path / "err.log", "w") as err:
        done = subprocess.run(
            [sys.executable, "-m", "gymfg_il.collect", *argv, "--out", str(tmp_path / "s")],
            stdout=subprocess.DEVNULL,
            stderr=err,
            env={**os.environ, "HF_HUB_OFFLINE": "1"},
            timeout=300,
        )
    text = (tmp_path / "err.log").read_text()
    assert done.returncode == 0 and "\r" not in text
    assert "episodes: 3/3 ep" in text
