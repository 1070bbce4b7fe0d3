"""The equipartition study's verdicts on synthetic replicas (the estimators themselves: tests/stats)."""
import numpy as np
import pytest

from openmm_symprk.stats import Estimate, agrees


def test_rows_are_compared_replica_by_replica():
    """Replicas share a large offset (each has its own total energy, the same for every row started from it):
    the paired difference resolves a row's 0.05 kJ/mol shift in the potential energy that the difference of
    the means (errors dominated by the offsets) cannot, and the match verdict follows it."""
    from openmm_symprk.studies.equipartition import presets
    from openmm_symprk.studies.equipartition.report import summarise

    rng = np.random.default_rng(7)
    cfg = presets.quick()
    shift = {"verlet 0.5 fs": 0.0, "verlet 3 fs": 0.05, "omelyan-2 4 fs": 0.0}
    cfg["models"] = {"spce": list(shift)}
    offsets = rng.normal(scale=0.3, size=8)  # per replica, kJ/mol per molecule
    t = np.arange(400) * 0.024
    runs = {}
    for label, d in shift.items():
        reps = []
        for r, off in enumerate(offsets):
            pe = (-45.5 + off + d + rng.normal(scale=0.02, size=t.size)) * cfg["n_waters"]
            tt = 300 + rng.normal(scale=5, size=t.size)
            arrays = {"t": t, "T_trans": tt, "T_rot": tt + rng.normal(scale=5, size=t.size), "pe": pe,
                      "etot": np.full(t.size, -1e4) + rng.normal(scale=1.0, size=t.size)}
            reps.append((arrays, {"status": "ok", "replica": r}))
        runs[("spce", label)] = reps
    rows = {r["label"]: r for r in summarise(cfg, runs)["models"]["spce"]["rows"]}
    far, near = rows["verlet 3 fs"], rows["omelyan-2 4 fs"]
    assert far["vs_ref"]["pe"]["mean"] == pytest.approx(0.05, abs=0.005)
    ref = rows["verlet 0.5 fs"]
    assert far["vs_ref"]["pe"]["se"] < 0.005 and far["pe"]["se"] > 10 * far["vs_ref"]["pe"]["se"]
    assert agrees(Estimate(**{k: far["pe"][k] for k in ("mean", "se", "replicas", "se_within", "se_between")}),
                  Estimate(**{k: ref["pe"][k] for k in ("mean", "se", "replicas", "se_within", "se_between")}))
    assert not far["matches_ref"] and near["matches_ref"]
