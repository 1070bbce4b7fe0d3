"""symprk fidelity: the --quick pipeline end to end, resuming, rows that cannot run, the reference pairing and the
extrapolated reference (the observables themselves: tests/studies/fidelity)."""
import copy
import glob
import json
import os
import types

import numpy as np
import pytest

from openmm_symprk.studies.core import jsonable
from openmm_symprk.studies.fidelity import presets
from openmm_symprk.studies.fidelity.cli import main
from openmm_symprk.analysis.observe import OBSERVABLES
from openmm_symprk.studies.fidelity.report import K_SE, summarise
from openmm_symprk.studies.fidelity.rowspec import UNAVAILABLE_THERMOSTAT, check_row, describe, label
from openmm_symprk.studies.fidelity.simulation import run_key, run_study


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """``symprk fidelity --quick`` as a user runs it (one worker: the test machine's cores are shared)."""
    import contextlib
    import io

    out = str(tmp_path_factory.mktemp("fidelity"))
    text = io.StringIO()
    with contextlib.redirect_stdout(text):
        rc = main(["--quick", "--out", out, "--workers", "1", "--no-progress"])
    return rc, out, text.getvalue()


def test_quick_prints_every_observable_for_every_row(quick):
    rc, out, text = quick
    assert rc == 0, text
    for row in presets.quick()["rows"]:
        assert label(row) in text
    for name in ("D", "tau1 dip ps", "tau2 dip ps", "tau1 HH ps", "tau2 HH ps", "w0 fs", "w Cmin", "w int fs",
                 "PE/mol", "Trot-Ttr K", "gOO r nm", "gOO height", "drift", "Yeh-Hummer", "cheapest NVE",
                 "issue #4280", "issue #2520", "extrapolated to h -> 0"):
        assert name in text, name
    for name in ("summary.txt", "equipartition.txt", "results.json", "fidelity.png", "fidelity-wall.png"):
        assert os.path.getsize(os.path.join(out, name)) > 0
    with open(os.path.join(out, "results.json")) as fh:
        res = json.load(fh)
    rows = {r["label"]: r for r in res["rows"]}
    assert res["reference"] == "verlet 0.5 fs" and rows["verlet 0.5 fs"]["wall_vs_ref"] == 1.0
    for lab, r in rows.items():
        thermostat = "SVR" in lab
        if r["status"] != "ok":  # only the package's thermostat rows may be unavailable, and only for that reason
            assert thermostat and r["status"].startswith(UNAVAILABLE_THERMOSTAT), (lab, r["status"])
            continue
        assert r["replicas"] == 2 and not r["failed"], lab
        for key in ("D", "tau2_dip", "tau2_hh", "w_zero", "w_min", "pe", "dT", "g_r", "g_h"):
            assert r["values"][key] is not None and r["values"][key]["se"] > 0, (lab, key)
        assert 1.0 < r["values"]["D"]["mean"] < 15.0 and 0.26 < r["values"]["g_r"]["mean"] < 0.30
        assert 5.0 < r["values"]["w_zero"]["mean"] < 40.0  # the librations: omega's first zero within tens of fs
        has_bath = r["row"]["kind"] in ("symprk", "nose-hoover")
        assert (r["values"]["drift"] is not None) == has_bath, lab
        assert r["evals_per_ps"] == pytest.approx(describe(r["row"])["evals_per_step"] * 1000 / r["row"]["step_fs"])
        assert r["s_per_ps"] > 0


def test_the_equipartition_view_is_made_from_the_same_runs(quick):
    """symprk equipartition's table (T_rot - T_trans, PE, drift, the Verlet trend) of the fidelity runs of the
    package's NVE rows: the same replicas, the same numbers as the fidelity table's."""
    _, out, _ = quick
    with open(os.path.join(out, "results.json")) as fh:
        res = json.load(fh)
    view = res["temperature_view"]["models"]["spce"]
    fid = {r["label"]: r for r in res["rows"]}
    assert view["reference"] == "verlet 0.5 fs"
    assert [r["label"] for r in view["rows"]] == ["verlet 0.5 fs", "verlet 1 fs", "verlet 2 fs", "verlet 3 fs",
                                                  "omelyan-2 4 fs", "pefrl 4 fs"]
    for r in view["rows"]:
        assert r["replicas"] == 2 and r["dT"]["mean"] == pytest.approx(fid[r["label"]]["values"]["dT"]["mean"])
        assert r["pe"]["mean"] == pytest.approx(fid[r["label"]]["values"]["pe"]["mean"])
    with open(os.path.join(out, "equipartition.txt")) as fh:
        assert "Published trend" in fh.read()


def test_replica_states_are_at_the_stated_density_with_zero_momentum(quick):
    from openmm_symprk.studies.equipartition.runs import build_box

    _, out, _ = quick
    cfg = presets.quick()
    (path,) = glob.glob(os.path.join(out, "states", "spce-*.npz"))
    with np.load(path) as d:
        v = d["v"]
    box = build_box(cfg, "spce")
    m = box.masses()
    assert len(v) == cfg["replicas"]
    for vr in v:
        p = (m[:, None] * vr).sum(axis=0)
        assert np.abs(p).max() < 1e-10 * np.abs(m[:, None] * vr).sum()  # zero to round-off
    edge = box.system.getDefaultPeriodicBoxVectors()[0][0]._value
    assert m.sum() * 1.66053906660e-24 / (edge ** 3 * 1e-21) == pytest.approx(0.997, rel=1e-4)


def test_a_second_call_reuses_every_run(quick):
    _, out, _ = quick
    logs = []
    again = run_study(presets.quick(), out, workers=1, timing=False, progress=False, log=logs.append)
    n = sum(1 for r in presets.quick()["rows"] if "collision_time_ps" not in r) * presets.quick()["replicas"]
    available = sum(r["replicas"] for r in again["rows"])
    assert available >= n and any(f"reusing {available} finished runs" in line for line in logs), logs
    with open(os.path.join(out, "results.json")) as fh:
        first = {r["label"]: r.get("values") for r in json.load(fh)["rows"]}
    assert {r["label"]: r.get("values") for r in jsonable(again)["rows"]} == first  # the same runs, summarised again


def test_an_interrupted_study_runs_only_what_is_missing(quick, tmp_path):
    """A copy of the finished study with one run lost (as if interrupted before it was stored): a call runs that
    one alone and stores it under the same key."""
    import shutil

    _, out, _ = quick
    copy_ = str(tmp_path / "copy")
    shutil.copytree(out, copy_, ignore=shutil.ignore_patterns(".lock"))
    lost = sorted(glob.glob(os.path.join(copy_, "runs", "*.json")))[0]
    os.remove(lost)
    os.remove(lost[:-5] + ".npz")
    logs = []
    summary = run_study(presets.quick(), copy_, workers=1, timing=False, progress=False, log=logs.append)
    stored = sum(r["replicas"] for r in summary["rows"])
    assert any(f"reusing {stored - 1} finished runs" in line for line in logs), logs
    assert os.path.exists(lost) and len(glob.glob(os.path.join(copy_, "runs", "*.json"))) == stored


def test_an_unavailable_thermostat_row_is_reported_not_run(tmp_path, monkeypatch):
    """A SymplecticIntegrator without the thermostat (TypeError on temperature=): the row is planned no run,
    stored nowhere and reported 'unavailable: needs the thermostat'; the other rows run."""
    import openmm_symprk.integrators as integrators

    real = integrators.SymplecticIntegrator

    def without_thermostat(*args, temperature=None, collision_time=None, random_seed=None, **kwargs):
        if temperature is not None:
            raise TypeError("__init__() got an unexpected keyword argument 'temperature'")
        return real(*args, **kwargs)

    monkeypatch.setattr(integrators, "SymplecticIntegrator", without_thermostat)
    cfg = presets.quick()
    cfg.update(replicas=1, length_ps=0.24, omega_ps=0.06, omega_max_lag_ps=0.03, msd_window_ps=[0.04, 0.1])
    cfg["rows"] = [{"kind": "symprk", "method": "verlet", "step_fs": 2.0},
                   {"kind": "symprk", "method": "verlet", "step_fs": 2.0, "collision_time_ps": 0.1}]
    logs = []
    summary = run_study(cfg, str(tmp_path), workers=1, timing=False, progress=False, log=logs.append)
    ref, svr = summary["rows"]
    assert ref["status"] == "ok" and ref["replicas"] == 1
    assert svr["status"].startswith(UNAVAILABLE_THERMOSTAT) and svr["replicas"] == 0
    assert len(glob.glob(str(tmp_path / "runs" / "*.json"))) == 1
    assert any("verlet 2 fs SVR 0.1 ps: unavailable: needs the thermostat" in line for line in logs)
    from openmm_symprk.studies.fidelity.report import format_summary

    assert "verlet 2 fs SVR 0.1 ps               unavailable: needs the thermostat" in format_summary(summary)


def test_an_unrelated_integrator_error_is_not_hidden(monkeypatch):
    import openmm_symprk.integrators as integrators
    from openmm_symprk.studies.fidelity.simulation.engines import availability

    def broken(*args, **kwargs):
        raise ValueError("stepSize must be positive")

    monkeypatch.setattr(integrators, "SymplecticIntegrator", broken)
    row = check_row({"kind": "symprk", "method": "verlet", "step_fs": 2.0, "collision_time_ps": 1.0})
    with pytest.raises(ValueError, match="stepSize"):
        availability(row, types.SimpleNamespace(system=None), 300.0)


# -- the summary on synthetic replicas ---------------------------------------------------------------------------
def _synthetic(cfg, rows, value, se=0.01, replicas=8, seed=3):
    """{label: [(arrays, info)]} whose every observable is value(row, replica) + noise of size se."""
    rng = np.random.default_rng(seed)
    grouped = {}
    for row in rows:
        reps = []
        for r in range(replicas):
            obs = {k: [value(row, r, k) + rng.normal(scale=se), se] for k, _, _ in OBSERVABLES}
            reps.append(({}, {"status": "ok", "replica": r, "obs": obs}))
        grouped[describe(row)["label"]] = reps
    return grouped


def _rows(*specs):
    return [check_row(dict(kind="symprk", method=m, step_fs=h)) for m, h in specs]


def test_rows_are_paired_with_the_reference_replica_by_replica():
    """Replicas differ by large offsets (each its own state), shared by every row started from it: the paired
    difference resolves a 0.05 shift that the difference of the means (errors ~0.3/sqrt(8)) cannot."""
    cfg = presets.quick()
    rows = _rows(("verlet", 0.5), ("verlet", 3.0), ("omelyan-2", 4.0))
    offsets = np.random.default_rng(1).normal(scale=0.3, size=8)
    shift = {3.0: 0.05, 0.5: 0.0, 4.0: 0.0}
    grouped = _synthetic(cfg, rows, lambda row, r, k: 2.0 + offsets[r] + shift[row["step_fs"]], se=0.005)
    res = {e["label"]: e for e in summarise(cfg, rows, grouped)["rows"]}
    far, near = res["verlet 3 fs"], res["omelyan-2 4 fs"]
    assert far["vs_ref"]["D"]["mean"] == pytest.approx(0.05, abs=0.01) and far["vs_ref"]["D"]["se"] < 0.005
    assert far["values"]["D"]["se"] > 10 * far["vs_ref"]["D"]["se"]
    assert not far["matches_ref"] and far["differs"] and near["matches_ref"]
    # the paired difference is the mean of the per-replica differences
    d = [a[1]["obs"]["pe"][0] - b[1]["obs"]["pe"][0] for a, b in zip(grouped["verlet 3 fs"], grouped["verlet 0.5 fs"])]
    assert far["vs_ref"]["pe"]["mean"] == pytest.approx(np.mean(d), rel=1e-12)
    summary = summarise(cfg, rows, grouped)
    assert summary["cheapest"]["NVE"]["label"] == "omelyan-2 4 fs" and summary["cheapest"]["NVT"] is None


def test_the_extrapolated_reference_recovers_each_replicas_h_to_zero_limit():
    """y = a_r + b h^2 exactly (tiny noise): the per-replica fit recovers a_r, so Verlet 0.5 fs is b/4 off the
    extrapolated reference, and a row equal to a_r shows no bias against it."""
    cfg = presets.quick()
    rows = _rows(("verlet", 0.5), ("verlet", 1.0), ("verlet", 2.0), ("verlet", 3.0), ("pefrl", 4.0))
    a = np.random.default_rng(2).normal(5.0, 0.5, size=8)
    b = 0.02

    def value(row, r, k):
        return a[r] if row["method"] == "pefrl" else a[r] + b * row["step_fs"] ** 2

    summary = summarise(cfg, rows, _synthetic(cfg, rows, value, se=1e-4))
    res = {e["label"]: e for e in summary["rows"]}
    assert res["verlet 0.5 fs"]["vs_extrapolated"]["tau2_hh"]["mean"] == pytest.approx(b * 0.25, abs=2e-4)
    assert res["verlet 3 fs"]["vs_extrapolated"]["D"]["mean"] == pytest.approx(b * 9, abs=2e-4)
    assert abs(res["pefrl 4 fs"]["vs_extrapolated"]["pe"]["mean"]) < 2e-4
    fit = summary["extrapolated"]["D"]
    assert fit["a"] == pytest.approx(a.mean(), abs=0.5 / np.sqrt(8) * K_SE) and fit["b"] == pytest.approx(b, rel=0.5)
    assert fit["steps_fs"] == [0.5, 1.0, 2.0, 3.0]


def test_a_published_effect_is_claimed_only_beyond_three_standard_errors():
    from openmm_symprk.studies.fidelity.report import claim

    per = {"a": {"D": {r: (4.7 + 0.01 * r, 0.05) for r in range(16)}},
           "b": {"D": {r: (5.4 + 0.01 * r, 0.05) for r in range(16)}},
           "c": {"D": {r: (5.38 + 0.01 * r, 0.05) for r in range(16)}}}
    yes = claim(per, "a", "b", -0.13, "friction")
    assert yes["reproduced"] is True and yes["consistent_with_published"] and yes["z"] < -K_SE
    unresolved = claim(per, "c", "b", -0.13, "friction")
    assert unresolved["reproduced"] is None and "not resolved" in unresolved["text"]
    assert claim(per, "b", "a", -0.13, "friction")["reproduced"] is False
    assert claim(per, "a", "missing", -0.13, "friction")["reproduced"] is None


# -- settings -------------------------------------------------------------------------------------------------------
def test_run_keys_follow_every_setting_and_are_pinned():
    cfg = presets.full()
    row = cfg["rows"][4]
    key = run_key(cfg, row, 3)
    other = copy.deepcopy(cfg)
    other["msd_window_ps"] = [1.0, 8.0]
    assert run_key(other, row, 3) != key and run_key(cfg, row, 2) != key and run_key(cfg, cfg["rows"][3], 3) != key
    other = copy.deepcopy(cfg)
    other["density_g_cm3"] = 0.9
    assert run_key(other, row, 3) != key
    assert key == run_key(presets.full(), presets.full()["rows"][4], 3) == "c73d85be549144a1"


@pytest.mark.parametrize("row, message", [
    ({"kind": "brownian", "step_fs": 2.0}, "kind must be one of"),
    ({"kind": "langevin", "step_fs": 2.0}, "missing: friction_per_ps"),
    ({"kind": "langevin", "step_fs": 2.0, "friction_per_ps": 1.0, "method": "verlet"}, "unknown: method"),
    ({"kind": "symprk", "method": "verlet", "step_fs": -1.0}, "step_fs must be a positive number"),
    ({"kind": "symprk", "method": "rk4", "step_fs": 1.0}, "rk4 is a reference method"),
])
def test_bad_rows_are_refused_with_the_reason(row, message):
    with pytest.raises(ValueError, match=message):
        check_row(row)


def test_the_cli_refuses_unknown_rows_before_building_anything(tmp_path, capsys):
    out = tmp_path / "never"
    assert main(["--quick", "--rows", "verlet 9 fs", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "unknown row(s) 'verlet 9 fs'" in err and "verlet 0.5 fs" in err and not out.exists()


def test_labels_name_every_option():
    labels = [label(r) for r in presets.full()["rows"]]
    assert len(set(labels)) == len(labels)
    assert "omelyan-2 4 fs SVR 1 ps" in labels and "langevin 4 fs friction 1/ps HMR 3 Da" in labels
    assert "mts-langevin 3/2 fs friction 1/ps" in labels and "dpd 2 fs friction 1/ps" in labels
