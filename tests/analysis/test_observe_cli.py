"""``symprk observe`` on trajectories no code of this package wrote: an AMBER NetCDF with velocities from the
MDAnalysis test files and the DCD of OpenMM's own DCDReporter (positions only); its figures are the analyses'
own, and files without water, without velocities or unreadable give clear messages."""
import json

import numpy as np
import pytest

mda = pytest.importorskip("MDAnalysis")
datafiles = pytest.importorskip("MDAnalysisTests.datafiles")

from openmm_symprk.analysis.cli import NEEDS_VELOCITIES  # noqa: E402
from openmm_symprk.analysis.universe import KineticTemperatures, Reorientation, SelfDiffusion  # noqa: E402
from openmm_symprk.cli import main as symprk  # noqa: E402


def main(argv):
    return symprk(["observe", *argv])

pytestmark = [pytest.mark.filterwarnings("ignore::DeprecationWarning"),
              pytest.mark.filterwarnings("ignore:Reader has no dt")]


def test_amber_netcdf_with_velocities(tmp_path, capsys):
    out = tmp_path / "obs.json"
    assert symprk(["observe", datafiles.PRM_NCBOX, datafiles.TRJ_NCBOX, "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "464 waters, 10 frames every 1 ps" in text and "T_rot - T_trans" in text
    data = json.loads(out.read_text())
    obs = data["observables"]
    u = mda.Universe(datafiles.PRM_NCBOX, datafiles.TRJ_NCBOX)
    water = u.select_atoms("resname WAT")
    d = SelfDiffusion(water).run()
    assert obs["D"]["value"] == pytest.approx(d.results.D, rel=1e-9) and obs["D"]["unit"] == "1e-5 cm2/s"
    # 10 frames, a window to 4.5 ps: no block error, and the note says why
    assert obs["D"]["se"] is None and np.isnan(d.results.se) and data["notes"]["D"] == d.results.se_note
    assert "no error bar: it comes from 5 blocks of the run (9 ps: blocks of 2 ps)" in text
    tau = Reorientation(water, vectors=("HH",), orders=(1,)).run().results.tau["HH"]["tau1"]
    assert obs["tau1_HH"]["value"] == pytest.approx(tau.tau, rel=1e-9)
    t = KineticTemperatures(water, by="residues").run().results
    assert obs["T_trans"]["value"] == pytest.approx(t.mean_translational, rel=1e-9)
    assert 250 < obs["T_rot"]["value"] < 350 and 0.26 < obs["g_r"]["value"] < 0.30
    # frames 1 ps apart: no omega ACF, and it says why; tau2 decays within two frames
    assert obs["w_zero"] is None and "librations" in data["notes"]["w_zero"]
    assert obs["tau2_HH"] is None and "store frames more often" in data["notes"]["tau2_HH"]
    assert data["velocities"] is True and data["n_waters"] == 464


def test_openmm_dcd_positions_only_with_a_progress_bar(plain_water, tmp_path, capsys):
    out = tmp_path / "obs.json"
    assert main([plain_water.pdb, plain_water.dcd, "--json", str(out), "--viscosity", "0.729",
                 "--temperature", "300"]) == 0
    captured = capsys.readouterr()
    assert "reading frames" in captured.err and "600/600" in captured.err  # 600 frames: a progress bar
    assert "positions only" in captured.out and "need velocities" in captured.out
    data = json.loads(out.read_text())
    obs, notes = data["observables"], data["notes"]
    for key in NEEDS_VELOCITIES:
        assert obs[key] is None and "needs velocities" in notes[key]
    d = SelfDiffusion(mda.Universe(plain_water.pdb, plain_water.dcd), viscosity_mpas=0.729, temperature_k=300).run()
    assert obs["D"]["value"] == pytest.approx(d.results.D, rel=1e-6)
    assert obs["D_inf"]["value"] == pytest.approx(d.results.D_infinite, rel=1e-6)
    for key in ("tau1_dipole", "tau2_dipole", "tau1_HH", "tau2_HH", "tau1_OH", "tau2_OH", "g_r", "g_h"):
        assert obs[key] is not None and np.isfinite(obs[key]["se"]) and obs[key]["se"] > 0, key
    assert main([plain_water.pdb, plain_water.dcd, "--stop", "50", "--progress", "never"]) == 0
    assert "reading frames" not in capsys.readouterr().err


def test_no_water_unreadable_files_and_bad_options_are_one_line_errors(tmp_path, capsys):
    assert main([datafiles.PSF, datafiles.DCD]) == 2
    assert "no water in the selection" in capsys.readouterr().err
    assert main([datafiles.PRM_NCBOX, str(tmp_path / "missing.nc")]) == 2
    assert "cannot read" in capsys.readouterr().err
    assert main([datafiles.PRM_NCBOX, datafiles.TRJ_NCBOX, "--viscosity", "0.3"]) == 2
    assert "both --viscosity and --temperature" in capsys.readouterr().err
    assert main([datafiles.PRM_NCBOX, datafiles.TRJ_NCBOX, "--select", "resname XYZ"]) == 2
    assert "matches no atom" in capsys.readouterr().err
