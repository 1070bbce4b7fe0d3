"""symprk fidelity: the --quick pipeline end to end, resuming, rows that cannot run, the reference pairing and the
extrapolated reference (the observables themselves: tests/studies/fidelity)."""
import copy
import glob
import json
import os

import numpy as np
import pytest

from openmm_symprk.studies.core import jsonable
from openmm_symprk.studies.fidelity import presets
from openmm_symprk.cli import main as symprk
from openmm_symprk.studies.fidelity.observables import OBSERVABLES
from openmm_symprk.studies.fidelity.report import K_SE, summarise
from openmm_symprk.studies.fidelity.rowspec import check_row, describe, label, to_row
from openmm_symprk.studies.fidelity.simulation import run_of, run_study


def main(argv):
    return symprk(["fidelity", *argv])


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
        assert r["status"] == "ok" and r["replicas"] == 2 and not r["failed"], lab
        for key in ("D", "tau2_dip", "tau2_hh", "w_zero", "w_min", "pe", "dT", "g_r", "g_h"):
            assert r["values"][key] is not None and r["values"][key]["se"] > 0, (lab, key)
        assert 1.0 < r["values"]["D"]["mean"] < 15.0 and 0.26 < r["values"]["g_r"]["mean"] < 0.30
        assert 5.0 < r["values"]["w_zero"]["mean"] < 40.0  # the librations: omega's first zero within tens of fs
        d = describe(r["row"])
        has_bath = d["family"] == "symprk" or lab.startswith(("nose-hoover", "openmm-verlet"))
        assert (r["values"]["drift"] is not None) == has_bath, lab
        assert r["evals_per_ps"] == pytest.approx(d["evals_per_step"] * 1000 / d["step_fs"])
        assert r["reference"] == res["references"][d["ensemble"]]
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
    # the package's NVE rows without HMR or MTS among the quick preset's rows, in their order
    assert [r["label"] for r in view["rows"]] == ["verlet 0.5 fs", "verlet 1 fs", "verlet 2 fs", "verlet 3 fs",
                                                  "omelyan-2 4 fs"]
    for r in view["rows"]:
        assert r["replicas"] == 2 and r["dT"]["mean"] == pytest.approx(fid[r["label"]]["values"]["dT"]["mean"])
        assert r["pe"]["mean"] == pytest.approx(fid[r["label"]]["values"]["pe"]["mean"])
    with open(os.path.join(out, "equipartition.txt")) as fh:
        assert "Published trend" in fh.read()


def test_replica_states_are_at_the_stated_density_with_zero_momentum(quick):
    from openmm_symprk.studies.core.replicas import water_box_scene as build_box

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
    n = len(presets.quick()["rows"]) * presets.quick()["replicas"]
    assert sum(r["replicas"] for r in again["rows"]) == n and any(f"reusing {n} finished runs" in line
                                                                   for line in logs), logs
    with open(os.path.join(out, "results.json")) as fh:
        first = {r["label"]: r.get("values") for r in json.load(fh)["rows"]}
    assert {r["label"]: r.get("values") for r in jsonable(again)["rows"]} == first  # the same runs, summarised again


def test_a_run_of_some_rows_times_them_in_turns_with_the_rows_timed_before(quick, tmp_path):
    """--rows on a folder with timings: the file keeps every row, all timed again in the same turns (a subset's own
    timings beside the earlier ones would compare two sessions' loads)."""
    import shutil

    _, out, _ = quick
    copy_ = str(tmp_path / "copy")
    shutil.copytree(out, copy_, ignore=shutil.ignore_patterns(".lock"))
    with open(os.path.join(copy_, "timings.json")) as fh:
        before = json.load(fh)
    cfg = presets.quick()
    cfg["rows"] = cfg["rows"][:2] + ["verlet 2 fs"]  # the references and one row, as --rows selects them
    run_study(cfg, copy_, workers=1, timing=True, progress=False, log=lambda *a: None)
    with open(os.path.join(copy_, "timings.json")) as fh:
        after = json.load(fh)
    assert set(after["s_per_ps"]) == set(before["s_per_ps"]) and len(after["s_per_ps"]) > 1
    assert after["s_per_ps"] != before["s_per_ps"] and all(v > 0 for v in after["s_per_ps"].values())


def test_a_row_that_blows_up_is_reported_and_left_out_of_the_timing(quick, tmp_path):
    """yoshida-4 at 8 fs (stability interval 1.57 for three evaluations) blows up on rigid water: its runs say at which
    step, the study finishes, and the timing in turns leaves the row out instead of stopping at it."""
    import shutil

    _, out, _ = quick
    copy_ = str(tmp_path / "copy")
    shutil.copytree(out, copy_, ignore=shutil.ignore_patterns(".lock"))
    cfg = presets.quick()
    cfg["rows"] = cfg["rows"][:2] + ["yoshida-4 8 fs"]
    summary = run_study(cfg, copy_, workers=1, timing=True, progress=False, log=lambda *a: None)
    (row,) = [r for r in summary["rows"] if r["label"] == "yoshida-4 8 fs"]
    assert row["replicas"] == 0 and row["failed"] and all(f.startswith("unstable at step") for f in row["failed"])
    with open(os.path.join(copy_, "timings.json")) as fh:
        timed = json.load(fh)["s_per_ps"]
    assert "yoshida-4 8 fs" not in timed and "verlet 0.5 fs" in timed


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


def test_rows_given_more_replicas_run_replica_by_replica_and_report_their_own_count(quick, tmp_path):
    """``row_replicas`` gives some rows more replicas than the others: the plan holds them, ordered replica by replica
    (a study stopped part way leaves every row within one replica of the others), a call runs only the missing
    ones, and the report counts each row's own replicas."""
    import shutil

    from openmm_symprk.studies.fidelity.simulation.study import FidelityStudy

    _, out, _ = quick
    copy_ = str(tmp_path / "copy")
    shutil.copytree(out, copy_, ignore=shutil.ignore_patterns(".lock"))
    cfg = presets.quick()
    more = cfg["rows"][5]
    cfg["row_replicas"] = {more: 3, cfg["rows"][0]: 3}
    study = FidelityStudy(cfg, copy_, workers=1, timing=False, progress=False, log=lambda *a: None)
    study.store = study.open_store()
    planned = study.plan()
    assert len(planned) == len(cfg["rows"]) * 2 + 2
    by_turn = sorted(planned, key=lambda run: -run.cost)  # the scheduler takes the costliest first
    assert [run.meta["replica"] for run in by_turn] == sorted(run.meta["replica"] for run in planned)
    first = [to_row(run.meta["row"]).evals_per_ps(True) for run in by_turn if run.meta["replica"] == 0]
    assert first == sorted(first, reverse=True)  # within a replica, the costliest row first
    assert {run.meta["row"] for run in planned if run.meta["replica"] == 2} == {label(more), label(cfg["rows"][0])}
    logs = []
    summary = run_study(cfg, copy_, workers=1, timing=False, progress=False, log=logs.append)
    n = len(cfg["rows"]) * 2
    assert any(f"reusing {n} finished runs" in line for line in logs), logs
    counts = {r["label"]: r["replicas"] for r in summary["rows"]}
    assert counts[label(more)] == counts[label(cfg["rows"][0])] == 3
    assert all(c == 2 for lab, c in counts.items() if lab not in (label(more), label(cfg["rows"][0])))
    # a report of more replicas than were run leaves the missing ones out, and builds no replica state
    states = glob.glob(os.path.join(copy_, "states", "*.npz"))
    before = [os.path.getmtime(p) for p in states]
    cfg["row_replicas"][more] = 5
    logs = []
    summary = run_study(cfg, copy_, workers=1, progress=False, log=logs.append, report_only=True)
    assert any("2 of" in line and "not finished" in line for line in logs), logs
    assert [os.path.getmtime(p) for p in states] == before
    assert {r["label"]: r["replicas"] for r in summary["rows"]}[label(more)] == 3


@pytest.mark.parametrize("given, message", [
    ({"verlet 9 fs": 3}, "row_replicas names 'verlet 9 fs', which is not among"),
    ({"verlet 0.5 fs": 0}, r"row_replicas\['verlet 0.5 fs'\] must be an integer >= 1, got 0"),
    ({"verlet 0.5 fs": 2.5}, "must be an integer >= 1, got 2.5")])
def test_bad_per_row_replica_counts_are_refused_naming_the_row(given, message):
    from openmm_symprk.studies.fidelity.simulation.study import check

    cfg = presets.quick()
    cfg["row_replicas"] = given
    with pytest.raises(ValueError, match=message):
        check(cfg)


def test_rows_chosen_keep_their_counts_and_replicas_given_set_them_aside():
    """--rows keeps the preset's per-row counts of the chosen rows; --replicas N gives every row N."""
    from openmm_symprk.studies.fidelity.cli import choose_rows
    from openmm_symprk.studies.fidelity.simulation.study import check, replica_counts

    cfg = presets.frontier()
    cfg["row_replicas"].update({"verlet 0.5 fs SVR 0.1 ps every 24": 17, "langevin 2 fs friction 1/ps": 15,
                                "langevin 3 fs friction 1/ps": 16})
    choose_rows(cfg, "langevin 2 fs friction 1/ps", None)
    counts = replica_counts(cfg, check(cfg))
    assert counts == {"verlet 0.5 fs": 12, "verlet 0.5 fs SVR 0.1 ps every 24": 17, "langevin 2 fs friction 1/ps": 15}
    # the preset: the NVT answer's rows at their committed counts, the reference at least as many as any of them
    cfg = presets.frontier()
    counts = replica_counts(cfg, check(cfg))
    assert {lab for lab, n in counts.items() if n > cfg["replicas"]} <= set(presets.FRONTIER_NVT_DECIDING)
    assert counts["verlet 0.5 fs SVR 0.1 ps every 24"] == max(counts.values()) == presets.FRONTIER_NVT_REPLICAS
    cfg = presets.frontier()
    choose_rows(cfg, "deciding", 8)
    cfg["replicas"] = 8
    assert set(replica_counts(cfg, check(cfg)).values()) == {8}


def test_a_study_without_its_extra_says_so_before_building_anything(tmp_path, monkeypatch):
    """Without tqdm (the studies extra) the study stops at once with the extra to install, before it builds replica
    states or runs anything."""
    import sys

    from openmm_symprk.support import MissingDependencyError

    monkeypatch.setitem(sys.modules, "tqdm", None)
    out = tmp_path / "f"
    expected = r"symprk fidelity \(progress bar\) needs tqdm.*openmm_symprk\[studies\]"
    with pytest.raises(MissingDependencyError, match=expected):
        run_study(presets.quick(), str(out), workers=1, progress=False)
    assert not out.exists()


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
    return [check_row(f"{m} {h:g} fs") for m, h in specs]


def _h(row):
    return describe(row)["step_fs"]


def test_rows_are_paired_with_the_reference_replica_by_replica():
    """Replicas differ by large offsets (each its own state), shared by every row started from it: the paired
    difference resolves a 0.05 shift that the difference of the means (errors ~0.3/sqrt(8)) cannot."""
    cfg = presets.quick()
    rows = _rows(("verlet", 0.5), ("verlet", 3.0), ("omelyan-2", 4.0))
    offsets = np.random.default_rng(1).normal(scale=0.3, size=8)
    shift = {3.0: 0.05, 0.5: 0.0, 4.0: 0.0}
    grouped = _synthetic(cfg, rows, lambda row, r, k: 2.0 + offsets[r] + shift[_h(row)], se=0.005)
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


def test_what_pairing_bought_is_the_unpaired_over_the_paired_variance():
    """The resolution table's pairing factor for PE: (SE_row^2 + SE_ref^2) / SE_paired^2. Replicas with large shared
    offsets buy a factor near (offset/noise)^2; replicas without (each row its own noise) buy about 1."""
    cfg = presets.quick()
    rows = _rows(("verlet", 0.5), ("verlet", 3.0))
    offsets = np.random.default_rng(1).normal(scale=0.3, size=16)
    shared = summarise(cfg, rows, _synthetic(cfg, rows, lambda row, r, k: 2.0 + offsets[r], se=0.01, replicas=16))
    alone = summarise(cfg, rows, _synthetic(cfg, rows, lambda row, r, k: 2.0, se=0.01, replicas=16))
    for summary, low, high in ((shared, 100.0, None), (alone, 0.3, 3.0)):
        res = {e["label"]: e for e in summary["rows"]}
        far, ref = res["verlet 3 fs"], res["verlet 0.5 fs"]
        gain = far["resolution"]["pe_pairing"]
        expected = (far["values"]["pe"]["se"] ** 2 + ref["values"]["pe"]["se"] ** 2) / far["vs_ref"]["pe"]["se"] ** 2
        assert gain == pytest.approx(expected, rel=1e-9)
        assert gain > low and (high is None or gain < high), gain


def test_the_extrapolated_reference_recovers_each_replicas_h_to_zero_limit():
    """y = a_r + b h^2 exactly (tiny noise): the per-replica fit recovers a_r, so Verlet 0.5 fs is b/4 off the
    extrapolated reference, and a row equal to a_r shows no bias against it."""
    cfg = presets.quick()
    rows = _rows(("verlet", 0.5), ("verlet", 1.0), ("verlet", 2.0), ("verlet", 3.0), ("pefrl", 4.0))
    a = np.random.default_rng(2).normal(5.0, 0.5, size=8)
    b = 0.02

    def value(row, r, k):
        return a[r] if row.startswith("pefrl") else a[r] + b * _h(row) ** 2

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
def run_key(cfg, row, replica):
    return run_of(cfg, row, replica).key


def test_run_keys_follow_every_setting_and_are_pinned():
    cfg = presets.full()
    row = "omelyan-2 4 fs"
    key = run_key(cfg, row, 3)
    other = copy.deepcopy(cfg)
    other["msd_window_ps"] = [1.0, 8.0]
    assert run_key(other, row, 3) != key and run_key(cfg, row, 2) != key and run_key(cfg, "verlet 3 fs", 3) != key
    other = copy.deepcopy(cfg)
    other["density_g_cm3"] = 0.9
    assert run_key(other, row, 3) != key
    other = copy.deepcopy(cfg)
    other["model"] = "tip3p"
    assert run_key(other, row, 3) != key
    # a label written another way is the same row; the references do not change a run
    other = copy.deepcopy(cfg)
    other["references"] = {"NVE": "verlet 0.5 fs"}
    assert run_key(other, "omelyan-2  4 fs", 3) == key
    assert key == run_key(presets.full(), "omelyan-2 4 fs", 3) == "79e3f5d46b06d938"


@pytest.mark.parametrize("row, message", [
    ("brownian 2 fs", "unknown method 'brownian'"),
    ("langevin 2 fs SVR 1 ps", "SVR does not apply"),
    ({"kind": "symprk", "method": "verlet", "step_fs": 2.0}, "a row is a label"),
    ("verlet -1 fs", "positive"),
    ("rk4 1 fs", "rk4 is a reference method"),
    ("rigid:verlet 2 fs", "not rigid-body engines"),
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
    assert labels == presets.full()["rows"] and len(set(labels)) == len(labels)  # written canonically, once each
    assert "omelyan-2 4 fs SVR 1 ps" in labels and "langevin 4 fs friction 1/ps HMR 3 Da" in labels
    assert "mts-langevin 3/2 fs friction 1/ps" in labels and "dpd 2 fs friction 1/ps" in labels
    assert set(presets.REFERENCES.values()) <= set(labels) and set(presets.DECIDING) <= set(labels)
    for lab in ("verlet 2 fs SVR 0.1 ps middle", "verlet 3 fs SVR 0.1 ps middle", "verlet 4 fs SVR 0.1 ps middle",
                "omelyan-2 5 fs SVR 0.1 ps", "omelyan-2 6 fs SVR 0.1 ps", "omelyan-2 5 fs", "omelyan-2 6 fs",
                "langevin 1 fs friction 0.1/ps", "langevin 3 fs friction 0.1/ps", "langevin 4 fs friction 0.1/ps",
                "openmm-verlet 1 fs", "openmm-verlet 2 fs", "verlet 4/2 fs", "omelyan-2 6/2 fs"):
        assert lab in labels, lab


def test_omelyan_rows_with_the_thermostat_sit_at_its_best_placement():
    """The omelyan-2 NVT rows run the thermostat at the ends: the placement methods.placement picks for it."""
    from openmm_symprk.methods.resolved import resolve
    from openmm_symprk.methods.placement import best_position

    m = resolve("omelyan-2")
    assert best_position(m.splitting.steps, m.stability) == "ends"
    assert all("middle" not in lab for lab in presets.full()["rows"] if lab.startswith("omelyan-2") and "SVR" in lab)


# -- issue 26: the NVT reference, the answer, the resolution, instabilities, committed results -------------------
def test_nvt_rows_are_paired_with_the_nvt_reference_and_nve_rows_with_the_nve_one():
    """NVE replicas share one set of offsets (each state's own energy), NVT replicas another (the thermostat pins
    the temperature): paired with its own reference, a 0.05 shift of an NVT row is resolved and an NVE row equal
    to its reference is not flagged; against the NVE reference the NVT shift would drown in the offsets."""
    cfg = presets.quick()
    rows = [check_row(r) for r in ("verlet 0.5 fs", "verlet 0.5 fs SVR 0.1 ps middle", "omelyan-2 4 fs",
                                   "omelyan-2 4 fs SVR 0.1 ps", "langevin 2 fs friction 0.1/ps")]
    refs = {"NVE": rows[0], "NVT": rows[1]}
    rng = np.random.default_rng(5)
    nve_off, nvt_off = rng.normal(scale=0.3, size=8), rng.normal(scale=0.3, size=8)

    def value(row, r, k):
        nvt = describe(row)["ensemble"] == "NVT"
        return 2.0 + (nvt_off[r] if nvt else nve_off[r]) + (0.05 if row.startswith("langevin") else 0.0)

    grouped = _synthetic(cfg, rows, value, se=0.005)
    summary = summarise(cfg, rows, grouped, references=refs)
    res = {e["label"]: e for e in summary["rows"]}
    assert summary["references"] == {"NVE": "verlet 0.5 fs", "NVT": "verlet 0.5 fs SVR 0.1 ps middle"}
    assert res["omelyan-2 4 fs"]["reference"] == "verlet 0.5 fs" and res["omelyan-2 4 fs"]["matches_ref"]
    lang, om = res["langevin 2 fs friction 0.1/ps"], res["omelyan-2 4 fs SVR 0.1 ps"]
    assert lang["reference"] == om["reference"] == "verlet 0.5 fs SVR 0.1 ps middle"
    assert lang["vs_ref"]["D"]["mean"] == pytest.approx(0.05, abs=0.01) and lang["vs_ref"]["D"]["se"] < 0.005
    assert not lang["matches_ref"] and om["matches_ref"]
    d = [a[1]["obs"]["D"][0] - b[1]["obs"]["D"][0]
         for a, b in zip(grouped[lang["label"]], grouped["verlet 0.5 fs SVR 0.1 ps middle"])]
    assert lang["vs_ref"]["D"]["mean"] == pytest.approx(np.mean(d), rel=1e-12)
    # the same rows against the NVE reference alone: the offsets do not cancel, nothing is resolved
    alone = {e["label"]: e for e in summarise(cfg, rows, grouped)["rows"]}
    assert alone["langevin 2 fs friction 0.1/ps"]["vs_ref"]["D"]["se"] > 10 * lang["vs_ref"]["D"]["se"]
    assert res["verlet 0.5 fs SVR 0.1 ps middle"]["is_reference"] and not res["verlet 0.5 fs SVR 0.1 ps middle"]["vs_ref"]["D"]


def test_the_nvt_rows_are_extrapolated_on_verlet_with_the_thermostat_in_the_middle():
    cfg = presets.quick()
    rows = [check_row(r) for r in ("verlet 0.5 fs", "verlet 2 fs", "verlet 0.5 fs SVR 0.1 ps middle",
                                   "verlet 2 fs SVR 0.1 ps middle", "verlet 3 fs SVR 0.1 ps middle",
                                   "verlet 2 fs SVR 0.1 ps", "omelyan-2 4 fs SVR 0.1 ps")]
    a, c = np.random.default_rng(2).normal(5.0, 0.5, size=(2, 8))
    b = 0.02

    def value(row, r, k):
        if row == "omelyan-2 4 fs SVR 0.1 ps":
            return c[r]
        if row == "verlet 2 fs SVR 0.1 ps":  # the ends placement: not a point of the NVT fit
            return 100.0
        return (c[r] if "SVR" in row else a[r]) + b * _h(row) ** 2

    summary = summarise(cfg, rows, _synthetic(cfg, rows, value, se=1e-4),
                        references={"NVE": rows[0], "NVT": rows[2]})
    res = {e["label"]: e for e in summary["rows"]}
    assert summary["extrapolated_nvt"]["D"]["steps_fs"] == [0.5, 2.0, 3.0]
    assert summary["extrapolated_nvt"]["D"]["b"] == pytest.approx(b, rel=0.05)
    assert abs(res["omelyan-2 4 fs SVR 0.1 ps"]["vs_extrapolated"]["D"]["mean"]) < 2e-4
    assert res["verlet 2 fs"]["vs_extrapolated"]["D"]["mean"] == pytest.approx(4 * b, abs=2e-4)


def test_the_answer_is_the_cheapest_match_and_its_speed_against_openmms_cheapest():
    table = [
        {"label": "ref", "ensemble": "NVT", "matches_ref": False, "is_reference": True, "family": "symprk",
         "s_per_ps": 8.0, "evals_per_ps": 2000, "evals_vs_ref": 1, "wall_vs_ref": 1, "max_z": None},
        {"label": "ours fast", "ensemble": "NVT", "matches_ref": True, "family": "symprk", "s_per_ps": 1.0,
         "evals_per_ps": 500, "evals_vs_ref": .25, "wall_vs_ref": .125, "max_z": 1.0},
        {"label": "ours faster but wrong", "ensemble": "NVT", "matches_ref": False, "family": "symprk",
         "s_per_ps": 0.5, "evals_per_ps": 250, "evals_vs_ref": .125, "wall_vs_ref": .06, "max_z": 5.0},
        {"label": "openmm", "ensemble": "NVT", "matches_ref": True, "family": "openmm", "s_per_ps": 3.0,
         "evals_per_ps": 1000, "evals_vs_ref": .5, "wall_vs_ref": .4, "max_z": 2.0},
        {"label": "openmm slow", "ensemble": "NVT", "matches_ref": True, "family": "openmm", "s_per_ps": 6.0,
         "evals_per_ps": 2000, "evals_vs_ref": 1, "wall_vs_ref": .8, "max_z": 0.5}]
    from openmm_symprk.studies.fidelity.report import answer

    a = answer(table, "NVT")
    assert a["label"] == a["ours"] == "ours fast" and a["openmm"] == "openmm" and a["by"] == "wall time"
    assert a["speedup_vs_openmm"] == pytest.approx(3.0)
    assert answer(table, "NVE") is None
    table[3]["s_per_ps"] = None  # not timed: picked by force evaluations, no ratio claimed
    a = answer(table, "NVT")
    assert a["by"] == "force evaluations" and a["speedup_vs_openmm"] is None
    from openmm_symprk.studies.fidelity.report import answer_lines

    lines = answer_lines({"rows": table, "cheapest": {"NVT": a}, "references": {"NVT": "ref"}, "reference": "ref"})
    assert lines[1] == ("  NVT: this package's cheapest match ours fast against OpenMM's cheapest match openmm: not "
                        "timed; force evaluations per ps, OpenMM's over ours: 2.00 (1000 against 500)")


def test_the_replicas_needed_scale_as_the_square_of_the_error():
    from openmm_symprk.studies.fidelity.report import resolution_needed

    assert resolution_needed(4, 0.1, 0.05) == 16 and resolution_needed(4, 0.01, 0.05) == 4
    assert resolution_needed(3, 0.0501, 0.05) == 4 and resolution_needed(4, None, 0.05) is None
    cfg = presets.quick()
    rows = _rows(("verlet", 0.5), ("verlet", 2.0))
    offsets = np.random.default_rng(1).normal(scale=0.3, size=8)
    grouped = _synthetic(cfg, rows, lambda row, r, k: 2.0 + offsets[r], se=0.05)
    e = {x["label"]: x for x in summarise(cfg, rows, grouped)["rows"]}["verlet 2 fs"]
    se_d = e["vs_ref"]["D"]["se"]
    assert e["resolution"]["D_rel_se"] == pytest.approx(se_d / e_ref_d(summarise(cfg, rows, grouped)), rel=1e-12)
    assert e["resolution"]["replicas_needed"] == max(
        resolution_needed(8, e["resolution"]["D_rel_se"], 0.05), resolution_needed(8, e["vs_ref"]["pe"]["se"], 0.05))


def e_ref_d(summary):
    return next(x for x in summary["rows"] if x["label"] == summary["reference"])["values"]["D"]["mean"]


def test_a_row_that_blows_up_is_recorded_unstable_with_its_step(tmp_path):
    """Verlet at 14 fs on the quick box, the package's and OpenMM's: the run stops and says at which step (OpenMM's
    integrator: within which steps); the study goes on and reports "unstable at step N" for the row."""
    from openmm_symprk.studies.fidelity.report import format_summary

    cfg = presets.quick()
    cfg.update(replicas=1, length_ps=0.24, omega_ps=0.06, omega_max_lag_ps=0.03, msd_window_ps=[0.04, 0.1],
               rows=["verlet 2 fs", "verlet 14 fs", "openmm-verlet 14 fs"], references={"NVE": "verlet 2 fs"})
    summary = run_study(cfg, str(tmp_path), workers=1, timing=False, progress=False, log=lambda *a: None)
    ref, *bad = summary["rows"]
    assert ref["replicas"] == 1
    for row in bad:
        (status,) = row["failed"]
        assert row["replicas"] == 0 and status.startswith("unstable at step ")
        assert 0 < int(status.split()[-1].split("-")[0]) <= 4  # within the first 50 fs (4 steps)
        assert f"{row['label']:36s} {status}" in format_summary(summary)


def test_unstable_names_the_step_of_either_kind_of_blow_up():
    import openmm as mm

    from openmm_symprk.integrators import SimulationBlowUpError
    from openmm_symprk.studies.fidelity.simulation.runs import unstable

    err = SimulationBlowUpError("the simulation blew up at integrator step 1234 with method 'verlet' at ...")
    assert unstable(err, 1000, 500) == "unstable at step 1234"
    assert unstable(mm.OpenMMException("Particle coordinate is NaN"), 1000, 50) == "unstable at step 1001-1050"
    assert unstable(ValueError("something else"), 0, 1) is None


def test_report_only_remakes_the_summary_from_the_committed_json_alone(quick, tmp_path):
    """The committed form of a study: states, each run's JSON and timings.json, no arrays, no results.  Report-only
    on it prints the same tables and verdicts as the study that ran; a run on it reuses every stored run."""
    import shutil

    from openmm_symprk.studies.fidelity.report import format_summary

    _, out, _ = quick
    kept = tmp_path / "committed"
    shutil.copytree(out, kept, ignore=shutil.ignore_patterns(".lock", "*.npz", "results.json", "*.png", "*.txt",
                                                             "table.md"))
    shutil.copytree(os.path.join(out, "states"), kept / "states", dirs_exist_ok=True)
    assert not glob.glob(str(kept / "runs" / "*.npz")) and glob.glob(str(kept / "states" / "*.npz"))
    with open(os.path.join(out, "summary.txt")) as fh:
        first = fh.read()
    again = run_study(presets.quick(), str(kept), workers=1, progress=False, log=lambda *a: None, report_only=True)
    assert format_summary(again) + "\n" == first
    with open(os.path.join(out, "table.md")) as fh, open(kept / "table.md") as fh2:
        assert fh.read() == fh2.read()
    assert again["temperature_view"] is None  # it needs the runs' time series, which are not committed
    logs = []
    resumed = run_study(presets.quick(), str(kept), workers=1, timing=False, progress=False, log=logs.append)
    n = sum(r["replicas"] for r in resumed["rows"])
    assert n and any(f"reusing {n} finished runs" in line for line in logs) and format_summary(resumed) + "\n" == first


def test_the_committed_results_load_and_report_as_committed(tmp_path, monkeypatch, capsys):
    """docs/fidelity.md's report-only commands on a copy of the committed data (docs/data/fidelity/<model>: states,
    each run's JSON, timings.json) print summary.txt and table.md byte for byte as committed: every stored run is
    found under its key, and the report of them is unchanged (the charts are left out here, for time)."""
    import re
    import shlex
    import shutil

    from openmm_symprk.studies.fidelity import report

    from openmm_symprk.studies.fidelity import frontier

    docs = os.path.join(os.path.dirname(__file__), "..", "..", "docs")
    with open(os.path.join(docs, "fidelity.md")) as fh:
        commands = dict.fromkeys(re.findall(r"^symprk fidelity ((?:--preset \S+ )?(?:--model \S+ )?--out "
                                            r"docs/data/fidelity/\S+ .*--report-only)", fh.read(), re.M))
    outs = {c.split("--out ")[1].split()[0]: c for c in commands}
    assert set(outs) == {f"docs/data/fidelity/{d}" for d in ("spce", "tip3p", "frontier-spce", "frontier-tip3p")}, commands
    monkeypatch.setattr(report, "chart", lambda *a, **k: None)
    monkeypatch.setattr(frontier, "frontier_chart", lambda *a, **k: None)
    for out, command in outs.items():
        argv = shlex.split(command.split("#")[0])
        i = argv.index("--out")
        committed = os.path.join(docs, "..", out)
        copy_ = str(tmp_path / os.path.basename(out))
        shutil.copytree(committed, copy_)
        capsys.readouterr()
        assert main(["--no-progress", *argv[:i], *argv[i + 2:], "--out", copy_]) == 0
        for name in ("summary.txt", "table.md"):
            with open(os.path.join(committed, name), "rb") as a, open(os.path.join(copy_, name), "rb") as b:
                assert a.read() == b.read(), (command, name)
        captured = capsys.readouterr()
        assert "report only" not in captured.err, (command, captured.err)
        if out.endswith("frontier-spce"):  # every planned run of the frontier is in the folder
            assert "planned runs are not finished" not in captured.out, captured.out


def test_the_frontier_preset_runs_every_nvt_family_on_three_steps_or_more():
    """The frontier's rows: every NVT row of the package thermostats with the reference's seed at the reference's
    collision time, on the 12-fs event grid where its step divides it (else every step); every family has two steps
    or more, every NVT family three or more (LangevinMiddle at friction 1/ps and 0.1/ps among them), the side rows
    (hypothesis tests) sit outside the families, and the tolerances name the observables the report fits."""
    from openmm_symprk.studies.core.rows import Row
    from openmm_symprk.studies.fidelity import presets
    from openmm_symprk.studies.fidelity.frontier import family_of
    from openmm_symprk.studies.fidelity.simulation.study import check

    cfg = presets.frontier()
    rows = check(cfg)
    side = set(cfg["side"])
    assert cfg["run_version"] == 3 and cfg["equilibrator"] == "svr" and "frozen" not in cfg and side < set(rows)
    ours_nvt = [Row.parse(r) for r in rows if Row.parse(r).ensemble == "NVT" and Row.parse(r).is_ours and r not in side]
    assert ours_nvt and all(r.seed == 1 and r.tau_ps == presets.NVT_TAU_PS and r.position in ("ends", "middle")
                            for r in ours_nvt)
    assert all(r.every * r.step_fs == presets.EVENT_FS if (presets.EVENT_FS / r.step_fs).is_integer() else r.every == 1
               for r in ours_nvt)
    families = {}
    for r in rows:
        if r not in cfg["references"].values() and r not in side:
            families.setdefault(family_of(r), set()).add(Row.parse(r).step_fs)
    assert all(len(steps) >= 2 for steps in families.values()), families
    nvt = {f: steps for f, steps in families.items() if " SVR " in f or f.startswith("langevin")}
    # where "auto" puts the thermostat (Verlet's ends rows answer the placement question at two steps)
    auto = {f: steps for f, steps in nvt.items() if f != "verlet SVR 0.1 ps"}
    assert all(len(steps) >= 3 for steps in auto.values()), auto
    assert {"langevin friction 1/ps", "langevin friction 0.1/ps", "predescu-3 SVR 0.1 ps"} <= set(nvt)
    assert len(nvt["omelyan-2 SVR 0.1 ps"]) >= 4
    assert family_of("omelyan-2 4 fs SVR 0.1 ps every 3") == family_of("omelyan-2 5 fs SVR 0.1 ps")
    from openmm_symprk.studies.fidelity.cli import select_rows

    deciding = select_rows(cfg, "deciding")
    assert set(deciding) == set(presets.FRONTIER_DECIDING) and set(deciding) < set(rows)
    assert all(len({Row.parse(r).step_fs for r in deciding if family_of(r) == f}) >= 2 for f in
               {family_of(r) for r in deciding if r not in cfg["references"].values()})
    keys = {k.removesuffix("_rel") for level in cfg["tolerances"].values() for k in level}
    from openmm_symprk.studies.fidelity.observables import OBSERVABLES
    assert keys <= {k for k, _, _ in OBSERVABLES}


def test_a_family_fits_its_bias_at_the_order_the_method_keeps_under_constraints():
    """c h^p with p the constrained order: compositions over RATTLE stay fourth order, a fourth-order splitting falls
    to second (pefrl), and OpenMM's integrators and every thermostat row are fitted at second order."""
    from openmm_symprk.studies.fidelity.frontier import bias_order

    assert [bias_order(r) for r in ("yoshida-4 3 fs", "suzuki-4 6 fs")] == [4, 4]
    assert [bias_order(r) for r in ("pefrl 6 fs", "omelyan-2 4 fs", "openmm-verlet 2 fs", "langevin 2 fs friction 0.1/ps",
                                    "yoshida-4 6 fs SVR 0.1 ps every 2")] == [2, 2, 2, 2, 2]


def test_the_issue_26_study_is_kept_as_it_ran(tmp_path):
    from openmm_symprk.studies.fidelity import presets
    from openmm_symprk.studies.fidelity.simulation import run_study

    with pytest.raises(ValueError, match="match-3se study is kept as it ran.*--report-only.*--preset frontier"):
        run_study(presets.full(), str(tmp_path))


def test_the_match_3se_preset_is_named_for_what_it_measures_and_reads_its_former_name(tmp_path, capsys):
    """The default preset is ``match-3se`` (each row within 3 SE of the reference); ``--preset issue26``, its former
    name, still reads as it with a note; it is kept as it ran, so only --report-only runs it."""
    from openmm_symprk.studies.fidelity.cli import build_parser

    assert build_parser().parse_args([]).preset == "match-3se"
    assert build_parser().parse_args(["--preset", "issue26"]).preset == "match-3se"
    assert "--preset issue26 is now called --preset match-3se" in capsys.readouterr().err
    assert "issue" not in build_parser().format_help()
    assert main(["--preset", "issue26", "--out", str(tmp_path / "new"), "--no-progress"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 2 and "the match-3se study is kept as it ran" in err[1] and not (tmp_path / "new").exists()


def test_the_studys_lowered_rows_follow_it():
    """The fidelity study's rows with a lowered target carry T (1 - c_T h^2 <w^2>) at the water box's measured
    <w^2> (presets.MEAN_SQUARE_FREQUENCY_FS2), to the label's 0.01 K."""
    from openmm_symprk.methods.catalogue import get_method
    from openmm_symprk.methods.shadow import shadow_target
    from openmm_symprk.studies.core.rows import Row
    from openmm_symprk.studies.fidelity import presets

    lowered = [lab for lab in presets.FRONTIER_ROWS if " T " in lab]
    assert len(lowered) >= 6 and sorted(lowered) == sorted(presets.LOWERED_ROWS["spce"])
    assert set(presets.LOWERED_ROWS) == set(presets.MEAN_SQUARE_FREQUENCY_FS2) == {"spce", "tip3p"}
    for model, labels in presets.LOWERED_ROWS.items():
        for row in map(Row.parse, labels):
            steps = get_method(row.method).splitting.steps
            omega2 = presets.MEAN_SQUARE_FREQUENCY_FS2[model]
            assert row.temperature == pytest.approx(300.0 * shadow_target(steps, "ends", row.step_fs ** 2 * omega2),
                                                    abs=0.011), (model, row.label)
    assert presets.MEAN_SQUARE_FREQUENCY_FS2["tip3p"] < presets.MEAN_SQUARE_FREQUENCY_FS2["spce"]


@pytest.mark.parametrize("model, n", [("spce", 12), ("tip3p", 8)])
def test_each_models_mean_square_frequency_is_its_committed_states(model, n):
    """presets.MEAN_SQUARE_FREQUENCY_FS2, which sets each model's lowered targets, is <F.M^-1.F>/(N_f kT) of the
    model's committed replica states (the first ``n``) to its four digits."""
    import glob

    import numpy as np

    from openmm_symprk.studies.core.replicas import water_box_scene
    from openmm_symprk.studies.fidelity import presets
    from openmm_symprk.systems.frequencies import mean_square_frequency

    found = glob.glob(os.path.join(os.path.dirname(__file__), "..", "..", "docs", "data", "fidelity",
                                   f"frontier-{model}", "states", f"{model}-*.npz"))
    assert len(found) == 1, f"one committed states file of {model} expected, found {found}"
    states = found[0]
    cfg = presets.frontier()
    x = np.load(states)["x"][:n]
    assert len(x) == n
    omega2 = mean_square_frequency(water_box_scene(cfg, model).system, list(x), 300.0, platform="CPU")["all"]
    assert omega2 * 1e-6 == pytest.approx(presets.MEAN_SQUARE_FREQUENCY_FS2[model], abs=1e-6)


def test_a_model_gets_its_own_lowered_rows_and_refuses_anothers():
    """--model (rowspec.for_model) swaps each row whose target is lowered for SPC/E for TIP3P's row of the same method,
    step and event grid, in the rows, the deciding rows and the per-row replica counts, and leaves out the SPC/E side
    rows TIP3P has none of; SPC/E's config is unchanged; a TIP3P study given SPC/E's lowered rows is refused with the
    rows and the fix named."""
    from openmm_symprk.studies.fidelity import presets
    from openmm_symprk.studies.fidelity.rowspec import for_model
    from openmm_symprk.studies.fidelity.simulation.study import check, replica_counts

    assert for_model(presets.frontier(), "spce") == presets.frontier()
    cfg = for_model(presets.frontier(), "tip3p")
    rows = check(cfg)
    spce, tip3p = set(presets.LOWERED_ROWS["spce"]), presets.LOWERED_ROWS["tip3p"]
    assert cfg["model"] == "tip3p" and not spce & set(rows) and set(tip3p) <= set(rows)
    assert len(rows) == len(presets.FRONTIER_ROWS) - 3
    assert set(tip3p) <= set(cfg["deciding"]) and not spce & set(cfg["deciding"] + cfg["side"])
    assert rows.index(tip3p[0]) == presets.FRONTIER_ROWS.index(presets.LOWERED_ROWS["spce"][0])
    counts = replica_counts(cfg, rows)
    assert all(counts[lab] == presets.FRONTIER_NVT_REPLICAS for lab in tip3p)
    assert for_model(dict(cfg), "tip3p") == cfg  # twice is once
    reordered = dict(presets.frontier(), rows=["verlet 0.5 fs", "verlet 0.5 fs SVR 0.1 ps every 24",
                                               "omelyan-2 5 fs T 299.32 K SVR 0.1 ps", "verlet 2 fs"])
    del reordered["row_replicas"]
    assert for_model(reordered, "tip3p")["rows"][2:] == ["omelyan-2 5 fs SVR 0.1 ps T 299.44 K", "verlet 2 fs"]
    plain = {"rows": ["verlet 2 fs", "verlet 2 fs"]}
    assert for_model(plain, "tip3p") == {"rows": ["verlet 2 fs", "verlet 2 fs"], "model": "tip3p"}
    assert set(presets.LOWERED_ROWS["spce"]) >= {lab for lab in presets.SIDE_ROWS + presets.FRONTIER_DECIDING
                                                 + presets.FRONTIER_NVT_DECIDING if " T " in lab}
    other = presets.frontier()
    other["model"] = "tip3p"
    with pytest.raises(ValueError, match=r"8 row\(s\) .* lowered for another water model's box, not tip3p's "
                                         r"\(.*'omelyan-2 5 fs SVR 0.1 ps T 299.32 K': tip3p's is 'omelyan-2 5 fs SVR "
                                         r"0.1 ps T 299.44 K'.*'verlet 3 fs SVR 0.1 ps every 4 T 296.93 K': none for "
                                         r"tip3p\); .*for_model\(cfg, 'tip3p'\)"):
        check(other)
