"""``symprk drift``: the HMR and exact-momentum studies end to end (--quick), resume, and the verdict logic."""
import glob
import json
import os

import numpy as np
import pytest

from openmm_symprk.studies.drift import presets
from openmm_symprk.cli import main as symprk
from openmm_symprk.studies.drift.report import format_summary
from openmm_symprk.studies.drift.study import run_study
from openmm_symprk.physics.temperature import R_KJ
from openmm_symprk.studies.drift.verdict import (claim_verdict, cost_verdict, magnitude, ratio, row_estimate,
                                                 run_drift)


def main(argv):
    return symprk(["drift", *argv])


# -- the verdict on synthetic drifts -----------------------------------------------------------------------------
def _reps(*values, se=0.01):
    return {r: (v, se) for r, v in enumerate(values)}


def test_claim_confirmed_when_the_row_drifts_clearly_less():
    v = claim_verdict(_reps(0.10, 0.12, 0.09), _reps(1.0, 1.1, 0.95), factor=10)
    assert v["magnitude"] == "smaller" and v["verdict"] == "confirmed"
    assert v["ratio"].mean == pytest.approx(0.31 / 3.05, rel=1e-9) and v["ratio"].se > 0
    assert v["difference"].mean == pytest.approx((0.31 - 3.05) / 3)


def test_claim_refuted_when_the_row_drifts_more_or_not_by_the_factor():
    assert claim_verdict(_reps(2.0, 2.1, 1.9), _reps(1.0, 1.1, 0.95))["verdict"] == "refuted"
    # smaller, but only by 1.25x: "about 10x less" is refuted, "less" alone is confirmed
    row, ref = _reps(0.8, 0.81, 0.79, se=0.001), _reps(1.0, 1.01, 0.99, se=0.001)
    assert claim_verdict(row, ref, factor=10)["verdict"] == "refuted"
    assert claim_verdict(row, ref, factor=None)["verdict"] == "confirmed"


def test_claim_not_resolved_within_the_errors():
    v = claim_verdict(_reps(0.5, 0.9, 0.7, se=0.3), _reps(1.0, 0.6, 0.8, se=0.3), factor=10)
    assert v["magnitude"] == "not resolved" and v["verdict"] == "not resolved at 3 SE"
    assert ratio(row_estimate(_reps(0.5)), row_estimate(_reps(0.01, se=0.1))) is None  # ref not resolved from 0


def test_magnitude_uses_both_signs():
    """|a| < |b| needs b - a and b + a resolved with the sign of b: a drift of the opposite sign and larger
    magnitude is larger, not smaller."""
    ref = _reps(-1.0, -1.0, -1.0, se=0.01)
    assert magnitude(_reps(0.9, 0.9, 0.9, se=0.01), ref) == "smaller"
    assert magnitude(_reps(1.2, 1.2, 1.2, se=0.01), ref) == "larger"
    assert magnitude(_reps(-1.2, -1.2, -1.2, se=0.01), ref) == "larger"
    assert magnitude(_reps(1.0, 1.0, 1.0, se=0.01), ref) == "not resolved"


def test_cost_verdict():
    off = _reps(1e-3, 1.1e-3, 0.9e-3, se=1e-5)
    assert cost_verdict(_reps(2e-3, 2.1e-3, 1.9e-3, se=1e-5), off).startswith("costs")
    assert cost_verdict(_reps(1e-4, 1.1e-4, 0.9e-4, se=1e-5), off).startswith("improves")
    assert cost_verdict(_reps(1e-3, 1.1e-3, 0.9e-3, se=1e-3), off).startswith("no difference")


def test_run_drift_recovers_a_known_slope_in_kt_per_ns_per_dof():
    rng = np.random.default_rng(3)
    n_dof, temp, slope = 1000, 300.0, 2e-3  # kT/ns/DOF
    t = np.linspace(0.0, 100.0, 1001)  # ps
    e = slope * R_KJ * temp * n_dof * t / 1e3 + rng.normal(0.0, 5.0, t.size)
    d, se = run_drift(t, e, n_dof, temp)
    assert se > 0 and abs(d - slope) < 4 * se
    with pytest.raises(ValueError, match="n_dof"):
        run_drift(t, e, 0, temp)


# -- the pipelines end to end --------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def hmr(tmp_path_factory):
    out = str(tmp_path_factory.mktemp("hmr"))
    logs = []
    summary = run_study(presets.hmr(quick=True), out, progress=False, log=logs.append)
    return out, summary, logs


def _states(out, scene):
    from openmm_symprk.studies.drift.study import states_key

    with np.load(os.path.join(out, "states", f"{scene}-{states_key(presets.hmr(quick=True), scene)}.npz")) as d:
        return d["x"], d["v"]


def test_hmr_quick_measures_every_row_with_an_error(hmr):
    out, summary, _ = hmr
    assert [r["name"] for r in summary["rows"]] == ["verlet 4 fs HMR", "OpenMM Verlet 4 fs HMR", "verlet 2 fs",
                                                    "OpenMM Verlet 2 fs"]
    for r in summary["rows"]:
        assert r["replicas_done"] == 3 and not r["failed"] and not r["skipped"]
        assert np.isfinite(r["drift"]["mean"]) and r["drift"]["se"] > 0 and r["drift"]["replicas"] == 3
        assert len(r["per_replica"]) == 3 and all(v[1] > 0 for v in r["per_replica"].values())
        assert r["wall_s_per_ps"] > 0
    main_cmp, control = summary["comparisons"]
    assert (main_cmp["row"], main_cmp["ref"], main_cmp["factor"]) == ("verlet 4 fs HMR", "OpenMM Verlet 4 fs HMR", 10.0)
    for c in (main_cmp, control):
        assert c["verdict"] in ("confirmed", "refuted", "not resolved at 3 SE")
        assert c["difference"]["se"] > 0 and c["speed_ratio"] > 0
    text = format_summary(summary)
    assert "verlet 4 fs HMR" in text and "claim: less, about 10x" in text
    with open(os.path.join(out, "results.json")) as fh:
        assert json.load(fh)["comparisons"][0]["verdict"] == main_cmp["verdict"]


def test_replicas_are_independent(hmr):
    out, summary, _ = hmr
    for scene in ("villin-vacuum-hmr", "villin-vacuum"):
        x, v = _states(out, scene)
        assert len(x) == 3
        for a in range(3):
            for b in range(a + 1, 3):
                assert not np.allclose(v[a], v[b]) and not np.allclose(x[a], x[b])
    drifts = [d[0] for d in summary["rows"][0]["per_replica"].values()]
    assert len(set(drifts)) == 3
    # the HMR scene has heavier hydrogens than the plain one
    from openmm_symprk.studies.core.scenes import build

    plain, heavy = build("villin-vacuum").system, build("villin-vacuum-hmr").system
    m = [plain.getParticleMass(i)._value for i in range(plain.getNumParticles())]
    mh = [heavy.getParticleMass(i)._value for i in range(heavy.getNumParticles())]
    assert min(mh) == pytest.approx(1.5) and min(m) < 1.1 and sum(m) == pytest.approx(sum(mh))


def test_resume_reuses_stored_runs_and_extends_replicas(hmr):
    out, summary, _ = hmr
    runs = sorted(glob.glob(os.path.join(out, "runs", "*.json")))
    assert len(runs) == 12
    stamps = {p: os.stat(p).st_mtime_ns for p in runs}
    logs = []
    again = run_study(presets.hmr(quick=True), out, progress=False, log=logs.append)
    assert any("reusing 12 finished runs" in m for m in logs)
    assert {p: os.stat(p).st_mtime_ns for p in runs} == stamps
    assert again["rows"][0]["per_replica"] == summary["rows"][0]["per_replica"]
    cfg = presets.hmr(quick=True, control=False)
    cfg["replicas"] = 4
    logs = []
    more = run_study(cfg, out, progress=False, log=logs.append)
    assert any("reusing 6 finished runs" in m for m in logs)
    assert len(glob.glob(os.path.join(out, "runs", "*.json"))) == 14
    assert [r["replicas_done"] for r in more["rows"]] == [4, 4]
    assert {k: v for k, v in more["rows"][0]["per_replica"].items() if k != "3"} == summary["rows"][0]["per_replica"]


def test_exact_momentum_quick_cli(tmp_path, capsys):
    out = str(tmp_path / "em")
    assert main(["exact-momentum", "--quick", "--platforms", "CPU", "--out", out, "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert "| CPU on | CPU off |" in text and "4.3e-04" in text
    with open(os.path.join(out, "results.json")) as fh:
        res = json.load(fh)
    assert [r["name"] for r in res["rows"]] == ["CPU off", "CPU on"]
    assert all(r["replicas_done"] == 3 and r["drift"]["se"] > 0 for r in res["rows"])
    assert [r["exact_momentum"] for r in res["rows"]] == [False, True]
    (cmp,) = res["comparisons"]
    assert cmp["verdict"].startswith(("costs", "improves", "no difference")) and cmp["difference"]["se"] > 0


def test_cli_errors_name_the_bad_value(tmp_path, capsys):
    assert main(["exact-momentum", "--quick", "--platforms", "OpenCL:quad", "--out", str(tmp_path)]) == 2
    assert "OpenCL:quad" in capsys.readouterr().err
    assert main(["hmr", "--quick", "--replicas", "0", "--out", str(tmp_path)]) == 2
    assert "replicas must be >= 1, got 0" in capsys.readouterr().err
    assert main(["hmr", "--quick", "--platforms", "CPU", "--out", str(tmp_path)]) == 2
    assert "exact-momentum study only" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["energy"])


def test_every_row_has_a_key_of_its_own_and_a_stored_run_is_reported(tmp_path):
    """Rows are keyed by their labels, scenes, platforms and replica states: every row of a study has a key of its own,
    and a run stored under its key is reported, not run again."""
    from openmm_symprk.studies.core import RunStore
    from openmm_symprk.studies.drift.study import DriftStudy, run_of

    for cfg in (presets.exact_momentum(quick=True, platforms=("CPU", "OpenCL:mixed")), presets.nvt(quick=True),
                presets.hmr(quick=True)):
        keys = {run_of(cfg, row, r).key for row in cfg["rows"] for r in range(2)}
        assert len(keys) == 2 * len(cfg["rows"])
    cfg = presets.exact_momentum(quick=True, platforms=("CPU",))
    cfg["replicas"] = 1
    study = DriftStudy(cfg, str(tmp_path), progress=False, log=lambda *a: None)
    row = cfg["rows"][0]
    RunStore(str(tmp_path)).put(run_of(cfg, row, 0).key, {"status": "ok", "n_dof": 10, "wall_per_ps": 1.0,
                                                         "row": row["name"], "replica": 0},
                                {"t": np.arange(4.0), "e": np.array([0.0, 1.0, 2.0, 3.1])})
    summary = study.run(report_only=True)
    assert [r["replicas_done"] for r in summary["rows"]] == [1, 0]
