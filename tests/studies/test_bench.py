"""``symprk bench``: the quick pipeline end to end, resumability, stability intervals, failure records.

No timing is asserted anywhere: wall-time ratios are reported by the bench, never tested."""
import json
import math
import os

import pytest

from openmm_symprk.studies.bench import presets, stability
from openmm_symprk.studies.core import scenes
from openmm_symprk.studies.bench.runs import RunSpec, execute
from openmm_symprk.studies.bench.sweep import SweepExistsError, run_sweep
from openmm_symprk.methods.catalogue import methods


def _mtimes(out):
    folder = os.path.join(out, "runs")
    return {f: os.stat(os.path.join(folder, f)).st_mtime_ns for f in os.listdir(folder) if f.endswith(".json")}


def _small_config():
    """Two cheap scenes, no stability: for the interruption test."""
    cfg = presets.select(presets.quick(), scenes=["harmonic", "water-rigid"], stability=False)
    cfg["scenes"]["harmonic"]["stability"] = presets.quick()["scenes"]["harmonic"]["stability"]
    cfg["methods"] = ["openmm-verlet", "verlet", "yoshida-4"]
    return cfg


def test_quick_pipeline_end_to_end_and_resume(tmp_path):
    from openmm_symprk.cli import main as symprk

    def main(argv):
        return symprk(["bench", *argv])

    out = str(tmp_path / "quick")
    assert main(["--quick", "--out", out, "--workers", "2", "--no-progress"]) == 0
    with open(os.path.join(out, "results.json")) as fh:
        res = json.load(fh)
    cfg = presets.quick()
    n_runs = sum(len(sc["steps_fs"]) for sc in cfg["scenes"].values()) * len(cfg["methods"])
    assert len(res["runs"]) == n_runs
    assert {r["method"] for r in res["runs"]} == set(cfg["methods"])
    assert len(res["references"]) == 1  # water-rigid; the toys have exact solutions
    # every record has its measurements (or is a recorded failure)
    for r in res["runs"]:
        assert r["status"] in ("ok", "failed"), r
        if r["status"] == "ok" and not r["failed"]:
            assert r["traj_error"] is not None and r["traj_error"] >= 0
            assert r["energy_error_per_dof"] is not None
            assert r["force_evals_per_ps"] > 0 and r["wall_per_ps"] > 0 and r["wall_vs_verlet"] > 0
    water = [r for r in res["runs"] if r["scene"] == "water-rigid" and r["method"] == "verlet"]
    assert all(r["dL_rel"] < 1e-9 and r["dP"] < 1e-8 and r["constraint_error"] < 1e-6 for r in water)
    # a higher-order method is more accurate at the same step on the molecular scene
    by = {(r["method"], r["step_fs"]): r for r in res["runs"] if r["scene"] == "water-rigid"}
    assert by[("yoshida-4", 1.0)]["traj_error"] < by[("verlet", 1.0)]["traj_error"]
    # stability searches ran and failures were recorded, not raised
    assert {s["scene"] for s in res["stability"]} == {"harmonic", "water-rigid"}
    assert any(r["failed"] for r in res["runs"])  # harmonic at 3 fs is beyond Verlet's limit (2.86 fs)
    charts = res["charts"]
    for name in ("bench_work_precision_water-rigid.png", "bench_stability.png", "bench_energy_harmonic.png",
                 "bench_speed.png"):
        path = os.path.join(out, "charts", name)
        assert path in charts and os.path.getsize(path) > 10_000
    assert os.path.getsize(os.path.join(out, "summary.txt")) > 0

    # a second call without --resume refuses to mix sweeps; with it, nothing is recomputed
    assert main(["--quick", "--out", out, "--no-progress"]) == 2
    before = _mtimes(out)
    again = run_sweep(cfg, out, workers=2, resume=True, charts=False, progress=False, log=lambda *a: None)
    assert again["stats"]["computed"] == 0
    assert again["stats"]["reused"] == len(before)
    assert _mtimes(out) == before
    assert main(["--summary", "--out", out]) == 0


def test_interrupted_sweep_continues_and_loses_nothing(tmp_path):
    out = str(tmp_path / "interrupted")
    cfg = _small_config()
    seen = []

    def stop_after_five(rec):
        seen.append(rec.key)
        if len(seen) == 5:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_sweep(cfg, out, workers=2, charts=False, progress=False, on_result=stop_after_five, log=lambda *a: None)
    kept = _mtimes(out)
    assert len(kept) >= 5 and {k + ".json" for k in seen} <= set(kept)
    with pytest.raises(SweepExistsError):
        run_sweep(cfg, out, workers=2, charts=False, progress=False, log=lambda *a: None)
    res = run_sweep(cfg, out, workers=2, resume=True, charts=False, progress=False, log=lambda *a: None)
    assert res["stats"]["reused"] == len(kept)
    assert res["stats"]["computed"] > 0
    after = _mtimes(out)
    assert {k: after[k] for k in kept} == kept  # nothing that was stored was recomputed
    # the resumed sweep equals an uninterrupted one in what it holds
    assert len(res["runs"]) == sum(len(s["steps_fs"]) for s in cfg["scenes"].values()) * len(cfg["methods"])
    assert all(s["status"] == "ok" for s in res["stability"])


def test_harmonic_stability_reproduces_catalogue_intervals():
    """Bisection on the harmonic toy (the compiled OpenMM programs) against the catalogue's intervals, within 1 %."""
    scene = scenes.build("harmonic", n=8)
    settings = stability.linear_settings(scene.linear["omega_max"], rel_tol=3e-3)  # the bracket within 0.3 %
    checked = []
    for name in ["openmm-verlet"] + [m.name for m in methods.values()]:
        cat = stability.catalogue_stability(name)
        if cat is None or not math.isfinite(cat):
            continue
        res = stability.largest_stable_step(scene, name, settings)
        assert res.status == "ok", res
        x = res.x_stable
        assert abs(x / cat - 1) < 0.01, (name, x, cat)
        checked.append(name)
    assert len(checked) >= 20


def test_failing_runs_are_recorded_not_raised():
    flex = scenes.build("water-flexible", n_waters=4)
    rec, _ = execute(RunSpec("water-flexible", "verlet 8 fs", 200, 10, timing_s=0.01), flex)
    assert rec.status == "failed" and rec.failed and rec.blew_up
    assert rec.failure.startswith(("blow-up", "energy"))
    assert rec.traj_error is None and rec.wall_per_ps is None
    rec, _ = execute(RunSpec("water-flexible", "openmm-verlet 8 fs", 200, 10), flex)
    assert rec.status == "failed"
    rigid = scenes.build("water-rigid", n_waters=4)
    rec, _ = execute(RunSpec("water-rigid", "gauss-2 1 fs", 10, 2), rigid)
    assert rec.status == "unsupported" and "constraints" in rec.failure
    rec, _ = execute(RunSpec("water-rigid", "no-such-method 1 fs", 10, 2), rigid)
    assert rec.status == "error" and "no-such-method" in rec.failure
    # a stability search on a scene where everything fails at the first probe still returns a result
    res = stability.largest_stable_step(flex, "verlet", {"h0_fs": 8.0, "cap_fs": 16.0, "grow": 2.0,
                                                         "rel_tol": 0.1, "probe_steps": 50, "samples": 5})
    assert res.status == "ok" and res.h_fail_fs is not None


def test_step_sizes_must_divide_the_run_length():
    cfg = presets.select(presets.quick(), scenes=["harmonic"], steps_fs=[0.7])
    with pytest.raises(ValueError, match="does not divide"):
        presets.check(cfg)


def test_dask_scheduler(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    cfg = presets.select(presets.quick(), scenes=["anharmonic"], methods=["verlet", "yoshida-4"], stability=False)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        res = run_sweep(cfg, str(tmp_path / "dask"), scheduler=cluster.scheduler_address, charts=False,
                        progress=False, log=lambda *a: None)
    assert res["stats"]["computed"] == 4
    assert all(r["status"] == "ok" for r in res["runs"] if r["step_fs"] == 1.0)


def test_records_are_typed_and_versioned(tmp_path):
    from openmm_symprk.studies.bench.records import SCHEMA_VERSION, RunRecord, SchemaError
    from openmm_symprk.studies.bench.store import Store

    rec = RunRecord("harmonic", "verlet", 1.0, 10)
    with pytest.raises(AttributeError, match="no field.*energy_eror"):
        rec.update(energy_eror=1.0)
    store = Store(str(tmp_path))
    store.put("k", rec.update(energy_error=0.5))
    back = store.get("k")
    assert isinstance(back, RunRecord) and back.energy_error == 0.5 and back.key == "k"
    data = back.to_json()
    assert data["schema"] == SCHEMA_VERSION
    with pytest.raises(SchemaError, match="schema 1"):
        RunRecord.from_json(dict(data, schema=1))
    with pytest.raises(SchemaError, match="unknown field.*bogus"):
        RunRecord.from_json(dict(data, bogus=1))


def test_production_scene_measures_drift_fluctuation_and_speed_against_a_baseline(tmp_path):
    """A small expensive-PME box through the production pipeline: MTS rows, OpenMM's MTSIntegrator, the summary
    table and the chart."""
    from openmm_symprk.studies.bench.aggregate import format_summary

    cfg = {"mode": "test", "methods": ["openmm-verlet"], "timing_s": 0.05, "threads": 1,
           "scenes": {"water-pme-accurate": {
               "params": {"box_nm": 1.8, "ewald_tolerance": 1e-4, "equilibrate_ps": 0.1}, "length_ps": 0.12,
               "samples": 12, "stability": None, "eval_s": 1e-3, "steps_fs": [2.0], "baseline": ["openmm-verlet", 2.0],
               "rows": [["openmm-verlet", 2.0], ["verlet", 2.0], ["verlet@mts2", 4.0], ["openmm-mts2", 4.0]]}}}
    res = run_sweep(cfg, str(tmp_path / "prod"), workers=1, progress=False, log=lambda *a: None)
    summary = res["production"]["water-pme-accurate"]
    assert summary["baseline"] == {"method": "openmm-verlet", "step_fs": 2.0}
    rows = {(r["method"], r["step_fs"]): r for r in summary["rows"]}
    assert set(rows) == {("openmm-verlet", 2.0), ("verlet", 2.0), ("verlet@mts2", 4.0), ("openmm-mts2", 4.0)}
    for r in rows.values():
        assert r["status"] == "ok" and r["ns_per_day"] > 0 and r["fluctuation"] > 0 and r["drift_err"] > 0, r
    assert rows[("openmm-verlet", 2.0)]["speedup"] == pytest.approx(1.0) and rows[("openmm-verlet", 2.0)]["matches"]
    text = format_summary(res)
    assert "NVE production runs" in text and "fastest row at the baseline's drift and fluctuation" in text
    assert any(p.endswith("bench_production_water-pme-accurate.png") for p in res["charts"])

    # --retime: every timed run is timed again; what the runs measured is kept, nothing is recomputed
    from openmm_symprk.studies.bench.sweep import retime_sweep

    again = retime_sweep(cfg, str(tmp_path / "prod"), rounds=1, charts=False, progress=False, log=lambda *a: None)
    assert again["stats"]["computed"] == 0
    before = {(r["method"], r["step_fs"]): r for r in res["runs"]}
    for r in again["runs"]:
        old = before[(r["method"], r["step_fs"])]
        assert r["retimed"] and not old["retimed"]
        assert r["wall_per_step"] > 0 and r["wall_per_step"] != old["wall_per_step"]
        for k in ("drift_kT_per_ns_per_dof", "energy_std_per_dof", "trace_de_per_dof", "E0"):
            assert r[k] == old[k], k
    with pytest.raises(ValueError, match="no finished runs"):
        retime_sweep(cfg, str(tmp_path / "empty"), progress=False, log=lambda *a: None)


def test_run_keys_of_stored_sweeps_do_not_change():
    """``--resume`` finds a sweep's stored runs by their keys (the row's label, the rest of the spec, the scene's
    fingerprint), which the one key function of the studies computes."""
    from openmm_symprk.studies.bench.sweep import run_of

    spec = RunSpec("villin-pme", "verlet 2 fs", 12000, 240, "run", timing_s=4.0, threads=2)
    assert run_of(spec, "0123456789abcdef").key == "ef6722c8b8739bc91c96"
    assert run_of(spec, "0123456789abcdee").key != "ef6722c8b8739bc91c96"  # another scene's state


def test_stored_production_runs_are_summarised_with_the_current_estimator():
    """A stored record keeps the drift its run computed; the summary takes the drift and its error again from the
    record's energy trace with openmm_symprk.stats.drift, so an old sweep re-summarised gets the current figures."""
    import numpy as np

    from openmm_symprk.physics.temperature import R_KJ
    from openmm_symprk.stats import drift
    from openmm_symprk.studies.bench.aggregate import production_summary

    rng = np.random.default_rng(3)
    t = list(np.arange(241) * 0.1)

    def run(method, slope):
        de = list(slope * np.asarray(t) + rng.normal(scale=1e-4, size=len(t)))
        return {"method": method, "step_fs": 2.0, "status": "ok", "failed": False, "wall_per_ps": 1.0,
                "energy_std_per_dof": 1e-4, "drift_kT_per_ns_per_dof": 123.0, "drift_kT_stderr": 9.0,
                "trace_t": t, "trace_de_per_dof": de}

    runs = [run("openmm-verlet", 0.0), run("verlet", 2e-5)]
    rows = production_summary({"baseline": ["openmm-verlet", 2.0]}, runs, temperature=300.0)["rows"]
    kT = R_KJ * 300.0
    for r, row in zip(runs, rows):
        d = drift(r["trace_t"], r["trace_de_per_dof"])
        assert row["drift"] == pytest.approx(d.slope * 1e3 / kT) and row["drift_err"] == pytest.approx(d.se * 1e3 / kT)
    assert rows[0]["matches"] and not rows[1]["matches"]  # 2e-5 kJ/mol/ps/DOF = 8e-3 kT/ns/DOF, many SE


def test_a_bench_run_is_keyed_by_its_row_label():
    """A run of the bench is keyed by its row's label (the bench's name and the step written as one row), the rest of
    its spec and its scene: rows that differ only by their inner method, their thermostat or their step are other
    runs, a row written another way the same."""
    from openmm_symprk.studies.bench.runs import bench_row
    from openmm_symprk.studies.bench.sweep import run_of

    scene = scenes.build("harmonic", n=8)
    fp = scene.payload()["fingerprint"]
    keys = {}
    for name, h in (("openmm-langevin", 2.0), ("omelyan-2/verlet@mts2", 4.0), ("omelyan-2@mts2", 4.0),
                    ("verlet", 300.0 / 1234), ("verlet", 2.0), ("velocity-verlet", 2.0)):
        spec = RunSpec("harmonic", bench_row(name, h, scene).label, 100, 10, timing_s=0.5)
        keys[(name, h)] = run_of(spec, fp).key
    assert keys[("verlet", 2.0)] == keys[("velocity-verlet", 2.0)]
    assert len(set(keys.values())) == len(keys) - 1
