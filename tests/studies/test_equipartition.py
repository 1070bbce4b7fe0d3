"""The equipartition study end to end on a tiny box: runs, summary, reuse of finished runs, errors."""
import copy
import os

import pytest

from openmm_symprk.studies.equipartition import presets, run_study
from openmm_symprk.cli import main as symprk
from openmm_symprk.studies.core.rows import Row
from openmm_symprk.studies.equipartition.report import format_summary


def main(argv):
    return symprk(["equipartition", *argv])


def _tiny():
    cfg = presets.quick()
    cfg.update(replicas=2, length_ps=0.06, settle_ps=0.012, equilibrate_ps=0.2, spacing_ps=0.05)
    cfg["models"] = {"spce": ["verlet 0.5 fs", "verlet 2 fs", "rigid:verlet 2 fs"]}
    return cfg


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = str(tmp_path_factory.mktemp("eq"))
    logs = []
    summary = run_study(_tiny(), out, workers=1, progress=False, log=logs.append)
    return out, summary, logs


def test_summary_has_every_row_with_error_bars(study):
    out, summary, _ = study
    res = summary["models"]["spce"]
    assert [r["label"] for r in res["rows"]] == ["verlet 0.5 fs", "verlet 2 fs", "rigid:verlet 2 fs"]
    for r in res["rows"]:
        assert r["replicas"] == 2 and not r["failed"]
        assert 150 < r["T_trans"]["mean"] < 450 and r["dT"]["se"] > 0 and r["pe"]["se"] > 0
        assert r["evals_per_ps"] == pytest.approx(1000.0 / r["step_fs"])
        assert r["s_per_ps"] > 0
    ref = res["rows"][0]
    assert res["reference"] == "verlet 0.5 fs" and ref["matches_ref"] and ref["wall_vs_ref"] == 1.0
    text = format_summary(summary)
    assert "T_rot-T_trans" in text and "Published trend" in text
    for name in ("summary.txt", "results.json", "equipartition.png"):
        assert os.path.getsize(os.path.join(out, name)) > 0


def test_a_second_call_reuses_every_finished_run(study):
    out, summary, _ = study
    logs = []
    again = run_study(_tiny(), out, workers=1, timing=False, progress=False, log=logs.append)
    assert any("reusing 6 finished runs" in line for line in logs)
    a, b = summary["models"]["spce"]["rows"], again["models"]["spce"]["rows"]
    assert [r["dT"]["mean"] for r in a] == [r["dT"]["mean"] for r in b]


def test_more_replicas_extend_the_study_and_reuse_every_finished_run(study):
    import glob

    import numpy as np

    out, summary, _ = study
    (path,) = glob.glob(os.path.join(out, "states", "spce-*.npz"))
    with np.load(path) as d:
        x2 = d["x"]
    cfg = _tiny()
    cfg["replicas"] = 3
    cfg["models"]["spce"] = cfg["models"]["spce"][:2]
    logs = []
    more = run_study(cfg, out, workers=1, timing=False, progress=False, log=logs.append)
    assert any("reusing 4 finished runs" in line for line in logs)
    assert any("3 replica states" in line and "1 new" in line for line in logs)
    with np.load(path) as d:
        assert len(d["x"]) == 3 and np.array_equal(d["x"][:2], x2)  # the first two states are kept as they were
    assert [r["replicas"] for r in more["models"]["spce"]["rows"]] == [3, 3]
    # a later call asking for fewer replicas still uses every finished one
    again = run_study(_tiny(), out, workers=1, timing=False, progress=False, log=lambda *a: None)
    assert [r["replicas"] for r in again["models"]["spce"]["rows"]] == [3, 3, 2]
    assert "  3 " in format_summary(again)


def test_a_changed_setting_does_not_reuse_runs():
    from openmm_symprk.studies.equipartition.study import run_of

    def key(cfg, model, label, replica):
        return run_of(cfg, model, label, replica).key

    cfg = _tiny()
    other = copy.deepcopy(cfg)
    other["length_ps"] = 0.1
    assert key(cfg, "spce", "verlet 2 fs", 0) != key(other, "spce", "verlet 2 fs", 0)
    assert key(cfg, "spce", "verlet 2 fs", 0) != key(cfg, "spce", "verlet 2 fs", 1)
    assert key(cfg, "spce", "verlet 2 fs", 0) != key(cfg, "tip3p", "verlet 2 fs", 0)
    assert key(cfg, "spce", "verlet 2 fs", 0) == key(cfg, "spce", "verlet:2", 0)  # one row, two spellings


def test_samples_fall_on_steps():
    assert [Row("verlet", h).steps_for(24.0) for h in (0.5, 1.0, 2.0, 3.0, 4.0)] == [48, 24, 12, 8, 6]


def test_bad_settings_are_refused(tmp_path, capsys):
    cfg = _tiny()
    cfg["models"]["spce"] = ["verlet 2 fs"]
    with pytest.raises(ValueError, match="reference row"):
        run_study(cfg, str(tmp_path), workers=1, progress=False)
    assert main(["--quick", "--rows", "verlt:2", "--out", str(tmp_path)]) == 2
    assert "Did you mean 'verlet'" in capsys.readouterr().err
    assert main(["--quick", "--models", "tip4p", "--out", str(tmp_path)]) == 2
    assert "unknown water model" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["--rows", "verlet"])
    out = tmp_path / "rk4"
    assert main(["--quick", "--rows", "rk4:2", "--out", str(out)]) == 2  # refused before anything is built
    assert "rk4 is a reference method" in capsys.readouterr().err and not out.exists()


def test_runs_on_a_dask_cluster(tmp_path):
    """The same study through the --scheduler path (an in-process Dask cluster): every run stored, a summary."""
    distributed = pytest.importorskip("dask.distributed")
    cfg = copy.deepcopy(presets.quick())
    cfg.update(replicas=1, length_ps=0.05)
    cfg["models"] = {"spce": ["verlet 0.5 fs", "omelyan-2 4 fs"]}
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        summary = run_study(cfg, str(tmp_path / "dask"), timing=False, progress=False, log=lambda *a: None,
                            scheduler=cluster.scheduler_address)
    rows = summary["models"]["spce"]["rows"]
    assert [r["replicas"] for r in rows] == [1, 1] and all("dT" in r for r in rows)


def test_run_keys_of_stored_studies_do_not_change():
    """A study's stored runs are found by their keys: a change of the key (or of what it hashes) orphans every
    stored run, so a re-summary would rerun them all.  Runs are keyed by their rows' labels (the key of run version
    3, the box at 0.997 g/cm^3 and replica states with zero total momentum)."""
    from openmm_symprk.studies.equipartition.study import run_of

    assert run_of(presets.full(), "spce", "omelyan-2 4 fs", 3).key == "404c7b31362732c3"


def test_stored_runs_are_found_by_their_keys_beyond_the_replicas_asked_for(tmp_path):
    """Every finished replica made with these settings is read back (also one beyond ``replicas``); a run of other
    settings, or one stored under a key of another form (the row as [method, step], retired), is not."""
    import numpy as np

    from openmm_symprk.studies.core import RunStore
    from openmm_symprk.studies.equipartition.study import load_runs, run_of
    from openmm_symprk.support.files import content_key

    cfg, store = _tiny(), RunStore(str(tmp_path))
    arrays = {k: np.arange(3.0) for k in ("t", "T_trans", "T_rot", "pe", "etot")}
    info = {"model": "spce", "row": "verlet 2 fs", "replica": 5, "status": "ok"}
    store.put(run_of(cfg, "spce", "verlet 2 fs", 5).key, info, arrays)
    store.put(run_of(dict(cfg, length_ps=1.0), "spce", "verlet 2 fs", 0).key, dict(info, replica=0), arrays)
    store.put(content_key({"model": "spce", "row": ["verlet", 2.0], "replica": 1}), dict(info, replica=1), arrays)
    found = load_runs(cfg, str(tmp_path))
    assert [i["replica"] for _, i in found[("spce", "verlet 2 fs")]] == [5] and not found[("spce", "verlet 0.5 fs")]
