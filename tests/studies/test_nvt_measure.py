"""``symprk nvt cost`` and ``symprk nvt drift`` end to end in their --quick modes (seconds): every row measured,
ratios positive and finite, drift estimates with an error bar, the tables print, the chart is written.  Nothing
here asserts a timing (the figures are in docs/thermostat.md, from the full commands)."""
import json
import math

import openmm as mm
import pytest

from openmm_symprk import plugin
from openmm_symprk.cli import main as symprk
from openmm_symprk.studies.drift import presets
from openmm_symprk.studies.nvt import cost, rows

needs_native = pytest.mark.skipif(not plugin.available(), reason="native plugin not built")


def test_every_cost_row_builds_its_integrator():
    from openmm_symprk.systems.scenes import water_box

    system, _, _ = water_box("tip3p", n_waters=64, cutoff_nm=0.5)
    expected = {"LangevinMiddle": (mm.LangevinMiddleIntegrator, 1), "NoseHoover (chain 3)": (mm.NoseHooverIntegrator, 1),
                "DPD": (mm.DPDIntegrator, 1), "MTSLangevin 1x1+0x2": (mm.MTSLangevinIntegrator, 3),
                "OpenMM Verlet (NVE)": (mm.VerletIntegrator, 1), "omelyan-2 + thermostat": (None, 2)}
    found = {name: row for name, row, _ in rows.cost_rows()}
    for name, (cls, evals) in expected.items():
        row = found[name]
        if cls is not None:
            assert isinstance(row.build(row.system_for(system)), cls)
        assert row.evals_per_step(True) == evals
    ig = found["verlet + thermostat /10"].replace(backend="custom").build(system)
    assert ig.getThermostatInterval() == 10
    assert ig.getTemperature().value_in_unit(mm.unit.kelvin) == rows.TEMPERATURE
    assert found["verlet (NVE)"].replace(backend="custom").build(system).thermostat is None


@needs_native
def test_cost_quick_measures_every_row(capsys):
    out = cost.run(scenes=("water",), quick=True, steps=2, rounds=3)
    table = out["water"]
    names = [name for name, _, _ in rows.cost_rows()]
    assert [r["row"] for r in table] == names
    for r in table:
        assert r["s_per_step"] > 0 and math.isfinite(r["ratio"]) and r["ratio"] > 0, r
        assert 0 < r["ratio_q25"] <= r["ratio"] <= r["ratio_q75"] and math.isfinite(r["ratio_q75"])
        assert r["ratio_best"] > 0 and math.isfinite(r["ratio_best"])
        assert math.isfinite(r["ratio_per_ps"]) and r["ratio_per_ps"] > 0
        assert (r["peer_ratio"] is None) == (not r["peer"]) and (r["peer_ratio"] is None or r["peer_ratio"] > 0)
    by = {r["row"]: r for r in table}
    assert by[cost.BASELINE]["ratio"] == 1.0 == by[cost.BASELINE]["ratio_q75"]  # block by block against itself
    assert by["omelyan-2 + thermostat"]["ratio_per_ps"] == pytest.approx(by["omelyan-2 + thermostat"]["ratio"] / 2)
    assert math.isfinite(cost.event_cost(table))
    printed = capsys.readouterr().out
    assert all(n in printed for n in names) and "one half thermostat event" in printed


def test_interleaved_keeps_every_block():
    from openmm_symprk.studies.core.timing import interleaved

    done = []
    out = interleaved({"a": done.append, "b": done.append}, {"a": 2, "b": 3}, rounds=4)
    assert done == [2, 3] * 4
    for t in out.values():
        assert len(t.blocks) == 4 and t.best == min(t.blocks)
        assert t.total == pytest.approx(sum(b * (t.steps // 4) for b in t.blocks))


@needs_native
def test_drift_quick_gives_estimates_with_errors_and_a_chart(tmp_path, capsys):
    """``symprk nvt drift`` is the drift study's nvt preset: every pair measured with an error bar, the NVT - NVE
    difference paired by replica, the table printed, the chart and the JSON written where asked."""
    chart, data = tmp_path / "img" / "nvt.png", tmp_path / "nvt.json"
    assert symprk(["nvt", "drift", "--quick", "--out", str(tmp_path / "out"), "--no-progress", "--chart", str(chart),
                   "--json", str(data)]) == 0
    result = json.loads(data.read_text())
    assert result["config"]["replicas"] == 1 and result["config"]["study"] == "nvt"
    names = [p[0] for p in presets.nvt_pairs(presets.NVT_QUICK)]
    assert [c["row"] for c in result["comparisons"]] == names
    rows = {r["name"]: r for r in result["rows"]}
    for c in result["comparisons"]:
        for name in (c["row"], c["ref"]):
            est = rows[name]["drift"]
            assert est is not None and math.isfinite(est["mean"]) and est["se"] > 0 and math.isfinite(est["se"])
        assert rows[c["row"]]["ensemble"] == "NVT" and rows[c["ref"]]["ensemble"] == "NVE"
        # the paired difference is the difference of the two rows (one replica)
        assert c["difference"]["mean"] == pytest.approx(rows[c["row"]]["drift"]["mean"] - rows[c["ref"]]["drift"]["mean"])
    printed = capsys.readouterr().out
    assert "NVT - NVE (paired)" in printed and all(n in printed for n in names)
    assert chart.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_bad_options_are_refused_with_their_value(capsys, tmp_path):
    with pytest.raises(SystemExit) as exc:
        symprk(["nvt", "cost", "--scenes", "water,protein"])
    assert exc.value.code == 2 and "protein" in capsys.readouterr().err
    assert symprk(["nvt", "drift", "--replicas", "0", "--out", str(tmp_path)]) == 2
    assert "replicas must be >= 1, got 0" in capsys.readouterr().err
    for bad, said in (("omelyan-2", "'omelyan-2': write method@step_fs"), ("verlet@-1", "'verlet@-1'"),
                      ("no-such-method@2", "no-such-method")):
        assert symprk(["nvt", "drift", "--rows", bad, "--out", str(tmp_path)]) == 2
        assert said in capsys.readouterr().err
    assert [p[0] for p in presets.nvt_pairs(["omelyan-4@4", "nosehoover@2"])] == ["pefrl 4 fs", "NoseHoover 2 fs"]


@needs_native
def test_every_drift_row_gives_a_full_finite_series():
    """The full study's rows (NoseHoover and OpenMM's Verlet included) on a small cluster: one sample per block from
    the start to the run's end, every effective energy finite, and the thermostat's heat-bath energy in it (NVT and
    NVE series of the same method differ)."""
    from openmm_symprk.studies.drift.runs import run_nve
    from openmm_symprk.systems.scenes import water_cluster

    sc = water_cluster(8, temperature=300.0)
    cfg = dict(presets.nvt(), length_ps=0.048, sample_ps=0.012, threads=1)
    series = {}
    for row in cfg["rows"]:
        arrays, info = run_nve(sc.system, sc.positions, sc.velocities, row, cfg, seed=1)
        assert info["status"] == "ok", info
        t, e = arrays["t"], arrays["e"]
        assert len(t) == 5 and t[-1] == pytest.approx(0.048) and all(map(math.isfinite, e))
        series[row["name"]] = e
    assert not (series["verlet 2 fs"] == series["verlet 2 fs NVE"]).all()
