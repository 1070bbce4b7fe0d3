"""The ``symprk`` command: what it prints, and one clear line and a non-zero exit for every bad input."""
import json
import os
import subprocess
import sys

import pytest

from openmm_symprk import plugin
from openmm_symprk.cli import main


def _run(argv, capsys):
    rc = main(argv)
    out = capsys.readouterr()
    return rc, out.out, out.err


def test_demo_prints_every_row_with_its_backend(capsys):
    rc, out, _ = _run(["demo", "--waters", "8", "--steps", "40", "--method", "verlet", "yoshida-4", "--platform",
                       "Reference"], capsys)
    assert rc == 0
    rows = [line.split() for line in out.splitlines() if line.startswith(("OpenMM VerletIntegrator ", "symprk "))]
    assert [r[:3] for r in rows] == [["OpenMM", "VerletIntegrator", "OpenMM"],
                                     ["symprk", "verlet", "native" if plugin.available() else "custom"],
                                     ["symprk", "yoshida-4", "native" if plugin.available() else "custom"]]
    ratio = float(rows[0][-1])
    assert ratio == 1.0 and int(rows[2][-2]) == 3  # the time ratio of Verlet itself; f/step of yoshida-4
    for r in rows:
        assert float(r[4]) < 1e-9  # |dP| of a 40-step run of an isolated cluster on Reference (double precision)


def test_demo_custom_backend(capsys):
    rc, out, _ = _run(["demo", "--waters", "4", "--steps", "10", "--method", "omelyan-2", "--backend", "custom"], capsys)
    assert rc == 0 and "symprk omelyan-2" in out and " custom " in out


@pytest.mark.parametrize("argv,message", [
    (["demo", "--platform", "Nosuch"], "unknown OpenMM platform 'Nosuch'; this installation has Reference"),
    (["demo", "--waters", "2", "--steps", "50", "--step-fs", "100", "--method", "verlet", "--platform", "Reference"],
     "blew up at integrator step"),
    (["demo", "--method", "verlett"], "Did you mean 'verlet'"),
    (["methods", "pefrll"], "Did you mean 'pefrl'"),
    (["fidelity", "--report-only", "--out", "no-such-symprk-study"], "no finished runs in no-such-symprk-study"),
    (["drift", "hmr", "--report-only", "--out", "no-such-symprk-study"], "no finished runs in no-such-symprk-study"),
])
def test_errors_are_one_line_and_exit_2(argv, message, capsys):
    rc, _, err = _run(argv, capsys)
    assert rc == 2 and message in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not os.path.exists("no-such-symprk-study")  # a report of nothing creates no folder


@pytest.mark.parametrize("argv,message", [(["demo", "--steps", "0"], "must be positive, got 0"),
                                          (["demo", "--step-fs", "-1"], "must be positive, got -1"),
                                          (["demo", "--waters", "x"], "'x' is not an integer"),
                                          (["demo", "--step-fs", "x"], "'x' is not a number")])
def test_bad_numbers_are_refused_by_the_parser(argv, message, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2 and message in capsys.readouterr().err


@pytest.mark.parametrize("content,name,message", [
    ("{not json", "t.json", "is not valid JSON"),
    ('{"A": [[0]]}', "t.json", "must hold a table with A and b"),
    ("A = [[0.0", "t.toml", "is not valid TOML"),
    ('{"A": [[0, 0], [1, 0]], "b": [0.5]}', "t.json", "b has 1 stages"),
])
def test_check_reports_malformed_files(content, name, message, tmp_path, capsys):
    path = tmp_path / name
    path.write_text(content)
    rc, _, err = _run(["check", str(path)], capsys)
    assert rc == 2 and message in err


def test_check_a_good_tableau(tmp_path, capsys):
    path = tmp_path / "leapfrog.json"
    path.write_text(json.dumps({"A": [[0, 0], [0.5, 0.5]], "b": [0.5, 0.5], "A_hat": [[0.5, 0], [0.5, 0]],
                                "b_hat": [0.5, 0.5]}))
    rc, out, _ = _run(["check", str(path)], capsys)
    assert rc == 0 and "symplectic for MD (condition (6)): True" in out and "measured order on Henon-Heiles: 2.0" in out
    assert main(["check", str(tmp_path / "missing.json")]) == 2


def test_methods_and_info(capsys):
    rc, out, _ = _run(["methods", "pefrl"], capsys)
    assert rc == 0 and "pefrl" in out and "sequence (applied left to right)" in out
    rc, out, _ = _run(["info"], capsys)
    assert rc == 0 and "platform Reference" in out and "catalogue: 31 methods" in out
    if "Reference" in plugin.thermostat_platforms():
        assert "NVT thermostat (temperature=): native" in out
    rc, _, err = _run(["info", "--require-native", "Nosuch"], capsys)
    assert rc == 2 and "does not serve Nosuch" in err


@pytest.mark.parametrize("argv,message", [
    (["--steps-fs", "0", "--quick"], "--steps-fs must be positive"),
    (["--platform", "Nosuch", "--quick"], "unknown OpenMM platform 'Nosuch'"),
    (["--scenes", "nosuch", "--quick"], "unknown scene"),
])
def test_bench_errors(argv, message, tmp_path, capsys):
    rc = main(["bench", "--out", str(tmp_path / "b"), "--no-progress", *argv])
    err = capsys.readouterr().err
    assert rc == 2 and message in err and "Traceback" not in err


def test_bench_out_must_be_a_writable_folder(tmp_path, capsys):
    afile = tmp_path / "results.txt"
    afile.write_text("x")
    assert main(["bench", "--quick", "--out", str(afile), "--no-progress"]) == 2
    assert "is a file" in capsys.readouterr().err


def test_two_sweeps_on_one_folder_are_refused(tmp_path):
    from openmm_symprk.studies.bench.sweep import SweepLockedError
    from openmm_symprk.studies.core import FolderLock

    lock = FolderLock(str(tmp_path), "symprk bench", SweepLockedError)
    code = ("import sys; from openmm_symprk.studies.bench.sweep import SweepLockedError\n"
            "from openmm_symprk.studies.core import FolderLock\n"
            "try:\n    FolderLock(sys.argv[1], 'symprk bench', SweepLockedError)\nexcept SweepLockedError as e:\n    print(e); sys.exit(3)\n")
    res = subprocess.run([sys.executable, "-c", code, str(tmp_path)], capture_output=True, text=True)
    assert res.returncode == 3 and "another symprk bench is running" in res.stdout
    lock.release()
    assert subprocess.run([sys.executable, "-c", code, str(tmp_path)]).returncode == 0
    assert SweepLockedError


def test_console_script_is_installed():
    res = subprocess.run([sys.executable, "-m", "openmm_symprk.cli", "methods"], capture_output=True, text=True)
    assert res.returncode == 0 and "sofroniou-spaletta-10" in res.stdout


def test_gpucheck_says_why_it_cannot_run_without_cuda(capsys):
    from openmm_symprk.studies.platforms.gpucheck import cuda_unavailable_reason

    if not cuda_unavailable_reason():
        pytest.skip("a CUDA platform with the native kernel is here: run `symprk gpucheck` itself")
    assert main(["gpucheck", "--quick"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("symprk gpucheck: error: ") and ("CUDA platform" in err or "CUDA kernel" in err)
    assert len(err.strip().splitlines()) == 1


def test_every_sub_command_runs_in_the_one_frame():
    """Each sub-command is a parser and an action, run by ``symprk``'s one frame: none has a ``main`` of its own that
    could answer errors its own way."""
    import importlib

    from openmm_symprk.cli import COMMANDS

    for name, cmd in COMMANDS.items():
        module = importlib.import_module(cmd.module)
        assert callable(module.run) and module.build_parser(f"symprk {name}").prog == f"symprk {name}", name
        assert module.__name__ == "openmm_symprk.cli" or not hasattr(module, "main"), name


def test_a_bug_keeps_its_traceback(monkeypatch, capsys):
    """A user's mistake is one line and status 2; an exception that is not one (here a KeyError) is a bug: raised."""
    from openmm_symprk import cli

    def broken(args):
        raise KeyError("a bug")

    monkeypatch.setattr(cli, "_methods", broken)
    with pytest.raises(KeyError, match="a bug"):
        main(["methods"])
    assert capsys.readouterr().err == ""


#: The fewest arguments each sub-command's parser takes (the others take none).
MINIMAL_ARGS = {"check": ["tableau.json"], "observe": ["water.pdb", "water.dcd"], "drift": ["hmr"], "nvt": ["known"]}
#: Exceptions of a bug's shape: no package error class, raised by Python itself or by a typo.
BUGS = [ValueError("not enough values to unpack (expected 2, got 1)"),
        ImportError("cannot import name 'nosuch' from 'openmm_symprk.stats'", name="openmm_symprk.stats")]


def _raising(monkeypatch, name, exc):
    """``symprk <name>``'s action raises ``exc`` once its options are parsed."""
    import importlib

    from openmm_symprk.cli import COMMANDS

    def run(args):
        assert args.command == name
        raise exc

    monkeypatch.setattr(importlib.import_module(COMMANDS[name].module), "run", run)
    return [name, *MINIMAL_ARGS.get(name, [])]


@pytest.mark.parametrize("bug", BUGS, ids=["ValueError", "ImportError"])
def test_a_bug_keeps_its_traceback_in_every_sub_command(monkeypatch, capsys, bug):
    """A ValueError or ImportError the package did not raise on purpose is a bug: it leaves the frame (Python prints
    its traceback), under every sub-command, as much as a user's error stays one line and status 2."""
    from openmm_symprk.cli import COMMANDS
    from openmm_symprk.support import InputError, MissingDependencyError

    monkeypatch.delenv("SYMPRK_DEBUG", raising=False)
    for name in COMMANDS:
        with pytest.raises(type(bug)) as info:
            main(_raising(monkeypatch, name, bug))
        assert info.value is bug, name
        assert capsys.readouterr().err == "", name
        for mistake in (InputError("--rows: unknown row 'verlett 2 fs'"),
                        MissingDependencyError("a chart needs matplotlib", package="matplotlib", extra="studies",
                                               feature="a chart")):
            assert main(_raising(monkeypatch, name, mistake)) == 2, name
            err = capsys.readouterr().err
            assert err == f"symprk {name}: error: {mistake}\n", (name, err)


def test_user_errors_are_the_ones_raised_on_purpose():
    import openmm as mm

    from openmm_symprk.cli import CommandError, is_user_error
    from openmm_symprk.integrators import SimulationBlowUpError
    from openmm_symprk.methods.catalogue import UnknownMethodError
    from openmm_symprk.methods.tableau import TableauError
    from openmm_symprk.plugin import NativeUnavailableError
    from openmm_symprk.studies.core import FolderLockedError
    from openmm_symprk.support import InputError

    on_purpose = [InputError("x"), TableauError("x"), UnknownMethodError("x"), SimulationBlowUpError("x"),
                  NativeUnavailableError("x"), FolderLockedError("x"), CommandError("x"),
                  mm.OpenMMException("Called setPositions() with the wrong number of positions"),
                  FileNotFoundError(2, "No such file or directory", "water.dcd")]
    assert all(is_user_error(e) for e in on_purpose)
    assert all(isinstance(e, ValueError) for e in on_purpose[:3])  # ``except ValueError`` still catches them
    bugs = [ValueError("x"), ImportError("x"), KeyError("x"), TypeError("x"), RuntimeError("x"), OSError("x")]
    assert not any(is_user_error(e) for e in bugs)


@pytest.mark.parametrize("switch", ["--debug", "SYMPRK_DEBUG"])
def test_debug_shows_a_user_errors_traceback(monkeypatch, capsys, switch):
    from openmm_symprk.support import InputError

    monkeypatch.delenv("SYMPRK_DEBUG", raising=False)
    argv = _raising(monkeypatch, "methods", InputError("unknown method 'verlett'"))
    if switch == "--debug":
        argv.append("--debug")
    else:
        monkeypatch.setenv("SYMPRK_DEBUG", "1")
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("Traceback (most recent call last):") and "InputError: unknown method 'verlett'" in err
    assert err.endswith("symprk methods: error: unknown method 'verlett'\n")
    monkeypatch.setenv("SYMPRK_DEBUG", "0")
    assert main(argv[:-1] if switch == "--debug" else argv) == 2
    assert capsys.readouterr().err == "symprk methods: error: unknown method 'verlett'\n"
