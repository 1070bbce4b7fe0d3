"""``symprk observe`` (and the classes under it) on inputs that gave wrong figures without a word (issue 36):
files of one run with a gap in time, wrapped positions without a box, a topology whose atom order is not the
trajectory's, a multi-model PDB (no times, one CRYST1), a --json path that cannot be written, NaN in the JSON,
and MDAnalysis' own traceback after the one-line error for an unreadable file.  The files are written here from
the frames of OpenMM's own DCD (conftest's plain_water: 64 SPC/E waters, a frame every 10 fs)."""
import json
import os
import stat
import subprocess
import sys
import threading

import numpy as np
import pytest

mda = pytest.importorskip("MDAnalysis")
datafiles = pytest.importorskip("MDAnalysisTests.datafiles")

from openmm_symprk.analysis.universe import Reorientation, SelfDiffusion  # noqa: E402
from openmm_symprk.cli import main as symprk  # noqa: E402


def main(argv):
    return symprk(["observe", *argv])

pytestmark = [pytest.mark.filterwarnings("ignore::DeprecationWarning"),
              pytest.mark.filterwarnings("ignore:Reader has no dt"), pytest.mark.filterwarnings("ignore:Found no"),
              pytest.mark.filterwarnings("ignore:Element information is missing"),
              pytest.mark.filterwarnings("ignore:Unit cell dimensions not found")]


class Files:
    """Paths of the files written from plain_water's frames."""


def _write(path, universe, frames, times=None, box=True):
    with mda.Writer(str(path), universe.atoms.n_atoms) as w:
        for k, f in enumerate(frames):
            ts = universe.trajectory[f]
            if times is not None:
                ts.time = times[k]
            if not box:
                ts.dimensions = None
            w.write(universe.atoms)


@pytest.fixture(scope="module")
def files(plain_water, tmp_path_factory):
    p = plain_water
    out, folder = Files(), tmp_path_factory.mktemp("observe_inputs")
    u = mda.Universe(p.pdb, p.dcd)
    # two files of one run, 0.5 ps not written between them (frames 0-99 and 150-249, a frame every 10 fs)
    out.a, out.b = folder / "a.xtc", folder / "b.xtc"
    _write(out.a, u, range(100), times=0.01 * np.arange(100))
    _write(out.b, u, range(150, 250), times=1.5 + 0.01 * np.arange(100))
    # the topology without its CRYST1, and the DCD's wrapped (whole) molecules without their box
    lines = open(p.pdb).readlines()
    out.nocryst = folder / "nocryst.pdb"
    out.nocryst.write_text("".join(line for line in lines if not line.startswith("CRYST1")))
    out.nobox = folder / "nobox.xtc"
    _write(out.nobox, u, range(100), box=False)
    # every atom wrapped on its own (molecules split across the box), no box; and continuous positions, no box
    c = mda.Universe(p.pdb)
    L = 10 * p.box
    c.load_new((10 * p.x[:100]) % L, format=mda.coordinates.memory.MemoryReader, dt=p.dt)
    out.split = folder / "split.xtc"
    _write(out.split, c, range(100), box=False)
    c.load_new(10 * p.x[:100], format=mda.coordinates.memory.MemoryReader, dt=p.dt)
    out.continuous = folder / "continuous.xtc"
    _write(out.continuous, c, range(100), box=False)
    # the topology listing each water's atoms H1 H2 O (the DCD stores O H1 H2)
    atoms = [line for line in lines if line.startswith(("ATOM", "HETATM"))]
    out.hho = folder / "hho.pdb"
    out.hho.write_text("".join([line for line in lines if line.startswith("CRYST1")] +
                               [atoms[i + j] for i in range(0, len(atoms), 3) for j in (1, 2, 0)] + ["END\n"]))
    # a multi-model PDB of frames 0-49: no times, one CRYST1 before the models
    out.multi = folder / "multi.pdb"
    with mda.Writer(str(out.multi), u.atoms.n_atoms, multiframe=True) as w:
        for _ in u.trajectory[:50]:
            w.write(u.atoms)
    out.pdb, out.dcd = p.pdb, p.dcd
    return out


def _err_line(capsys):
    captured = capsys.readouterr()
    lines = [line for line in captured.err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("symprk observe: error: "), captured.err
    return lines[0], captured.out


def test_a_gap_in_time_between_files_is_refused_naming_it(files, capsys):
    """Before: the frames were copied at the median interval, the 0.5 ps gap vanished and D was computed across
    it; now the gap is named with what to do, and --start/--stop analyse one piece."""
    assert main([files.pdb, str(files.a), str(files.b), "--progress", "never"]) == 2
    err, out = _err_line(capsys)
    assert "between frame 99 (t = 0.99 ps) and frame 100 (t = 1.5 ps) 0.51 ps pass where the other frames are " \
           "0.01 ps apart" in err and "--start 0 --stop 100" in err
    assert "--dt" not in err  # a stretch not written is not joined by --dt (refused there)
    assert out == ""  # refused before anything was computed
    assert main([files.pdb, str(files.a), str(files.b), "--stop", "100", "--progress", "never"]) == 0
    assert "100 frames every 0.01 ps" in capsys.readouterr().out
    # a file whose clock starts again: time goes back
    assert main([files.pdb, files.dcd, files.dcd, "--progress", "never"]) == 2
    err, _ = _err_line(capsys)
    assert "between frame 599 (t = 6 ps) and frame 600 (t = 0.01 ps) time goes back by 5.99 ps" in err
    assert "give it with --dt PS" in err  # a clock that starts again: --dt says the frames follow each other


def test_the_classes_name_the_gap_too(files):
    u = mda.Universe(files.pdb, [str(files.a), str(files.b)])
    with pytest.raises(ValueError, match=r"between frame 99 \(t = 0.99 ps\) and frame 100 \(t = 1.5 ps\).*"
                                         r"\.run\(start=, stop=\)"):
        SelfDiffusion(u).run()


def test_wrapped_positions_without_a_box_are_refused(files, tmp_path, capsys):
    """Before: centres of mass wrapped into a box the file does not store were taken as motion (D 2-5x too
    large, said only through 'g(r) needs a periodic box')."""
    assert main([str(files.nocryst), str(files.nobox)]) == 2
    err, out = _err_line(capsys)
    assert "jumps" in err and "about the width of the system" in err and "wrapped into a box the trajectory does " \
           "not store" in err and out == ""
    u = mda.Universe(str(files.nocryst), str(files.nobox))
    with pytest.raises(ValueError, match=r"SelfDiffusion: the centre of mass of molecule \d+ jumps [\d.]+ Angstrom "
                                         r"along [xyz] .*set_dimensions"):
        SelfDiffusion(u).run()
    # whole molecules that jump do not change a reorientation: it runs, and gives the curve of the boxed DCD
    c1 = Reorientation(u, vectors=("HH",), orders=(1,)).run().results.C["HH"]["C1"]
    ref = Reorientation(mda.Universe(files.pdb, files.dcd), vectors=("HH",), orders=(1,)).run(stop=100)
    np.testing.assert_allclose(c1, ref.results.C["HH"]["C1"], atol=1e-4)  # XTC keeps 0.01 Angstrom
    # atoms wrapped one by one split the molecules
    assert main([str(files.nocryst), str(files.split)]) == 2
    err, _ = _err_line(capsys)
    assert "is split in frame" in err and "wrapped into a periodic box the trajectory does not store" in err
    # continuous positions without a box are what they claim: D is the boxed DCD's
    out = tmp_path / "continuous.json"
    assert main([str(files.nocryst), str(files.continuous), "--json", str(out)]) == 0
    d = SelfDiffusion(mda.Universe(files.pdb, files.dcd)).run(stop=100).results.D
    assert json.loads(out.read_text())["observables"]["D"]["value"] == pytest.approx(d, rel=2e-3)


def test_the_topology_box_serves_frames_without_one(files, tmp_path, capsys):
    """The same boxless frames with a topology that has a CRYST1: its box is used, and said."""
    out = tmp_path / "nobox.json"
    assert main([files.pdb, str(files.nobox), "--json", str(out)]) == 0
    assert "box from the CRYST1 record of water.pdb (for 100 frames that store none)" in capsys.readouterr().out
    d = SelfDiffusion(mda.Universe(files.pdb, files.dcd)).run(stop=100).results.D
    data = json.loads(out.read_text())
    assert data["observables"]["D"]["value"] == pytest.approx(d, rel=2e-3) and "CRYST1" in data["box_from"]


def test_a_topology_in_another_atom_order_is_refused(files, capsys):
    """Before: H1 H2 O in the topology against O H1 H2 in the trajectory took an H for the O (T_trans 2279 K
    from velocities); now the molecules' distances are checked in the first frame."""
    assert main([str(files.hho), files.dcd, "--progress", "never"]) == 2
    err, out = _err_line(capsys)
    assert ("molecule 0 (residue HOH 1) is not water in the first frame: O-H 1.00 and 1.63 Angstrom, H-H 1.00 "
            "Angstrom, where water has O-H 0.8-1.2 and H-H 1.3-1.9 Angstrom; 64 of 64 molecules are outside") in err
    assert "order of the trajectory's" in err and out == ""
    with pytest.raises(ValueError, match=r"Reorientation: molecule 0 \(residue HOH 1\) is not water"):
        Reorientation(mda.Universe(str(files.hho), files.dcd)).run(stop=3)


def test_a_multi_model_pdb_takes_dt_and_keeps_its_box(files, tmp_path, capsys):
    """A multi-model PDB stores no times (read as 1 ps apart) and one CRYST1, which MDAnalysis applies to no
    frame: --dt gives the interval, the CRYST1 is kept, and D is that of the DCD's same frames."""
    out = tmp_path / "multi.json"
    assert main([str(files.multi), str(files.multi), "--dt", "0.01", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "50 frames every 0.01 ps (--dt)" in text and "box from the CRYST1 record of multi.pdb" in text
    data = json.loads(out.read_text())
    assert data["dt_ps"] == pytest.approx(0.01) and data["dt_from"] == "--dt" and data["observables"]["g_r"]
    ref = SelfDiffusion(mda.Universe(files.pdb, files.dcd)).run(stop=50).results.D
    assert data["observables"]["D"]["value"] == pytest.approx(ref, rel=2e-3)
    assert main([str(files.multi), str(files.multi), "--stop", "20"]) == 0
    assert "20 frames every 1 ps (no times in the file: taken 1 ps apart; give the interval with --dt PS)" in \
        capsys.readouterr().out
    for bad in ("0", "-0.5", "nan"):
        assert main([str(files.multi), str(files.multi), "--dt", bad]) == 2
        err, _ = _err_line(capsys)
        assert f"--dt must be a positive number of ps (the time between the trajectory's frames), got {bad}" in err


@pytest.mark.parametrize("where", ["missing/obs.json", ".", "/proc/symprk-observe.json"])
def test_an_unwritable_json_path_is_refused_before_the_analysis(where, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main([datafiles.PRM_NCBOX, datafiles.TRJ_NCBOX, "--json", where]) == 2
    err, out = _err_line(capsys)
    assert f"--json {where}" in err and out == ""  # said before the analysis, which did not run
    assert ("does not exist" if where.startswith("missing") else "is a folder" if where == "." else
            "cannot write in /proc") in err
    assert os.listdir(tmp_path) == []


def test_the_json_is_strict_and_written_whole(tmp_path, capsys):
    """Missing errors are null, not NaN (which strict JSON parsers refuse); the file is replaced whole, no
    temporary file left beside it."""
    out = tmp_path / "obs.json"
    out.write_text("an older file\n")
    assert main([datafiles.PRM_NCBOX, datafiles.TRJ_NCBOX, "--stop", "3", "--json", str(out)]) == 0
    assert "T_trans" in capsys.readouterr().out

    def refuse(constant):
        raise ValueError(f"{constant} is not JSON")

    data = json.loads(out.read_text(), parse_constant=refuse)
    t = data["observables"]["T_trans"]
    assert t["se"] is None and 250 < t["value"] < 350  # 3 frames: no block error
    assert os.listdir(tmp_path) == ["obs.json"]


def test_the_json_goes_through_a_symlink_and_into_a_fifo(tmp_path, capsys):
    """The whole-file replacement (temp file + os.replace) is for regular files: a symlink keeps pointing at the
    file it names, which is replaced; a FIFO (or a device: /dev/stdout, /dev/null) is written into, not replaced
    by a regular file."""
    real, link = tmp_path / "real.json", tmp_path / "link.json"
    real.write_text("an older file\n")
    link.symlink_to(real)
    assert main([datafiles.PRM_NCBOX, datafiles.TRJ_NCBOX, "--json", str(link)]) == 0
    assert link.is_symlink() and json.loads(real.read_text())["n_waters"] == 464
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(open(fifo).read()), daemon=True)
    reader.start()
    assert main([datafiles.PRM_NCBOX, datafiles.TRJ_NCBOX, "--json", str(fifo)]) == 0
    reader.join(60)
    assert stat.S_ISFIFO(os.stat(fifo).st_mode) and json.loads(got[0])["n_waters"] == 464
    assert sorted(os.listdir(tmp_path)) == ["link.json", "pipe", "real.json"]
    capsys.readouterr()


SCRIPT = "import sys; from openmm_symprk.cli import main; sys.exit(main(sys.argv[1:]))"


@pytest.mark.parametrize("content", [None, b"", b"\x8f\x01garbage" * 200])
def test_an_unreadable_trajectory_leaves_one_line_on_stderr(content, tmp_path):
    """MDAnalysis' half-built reader used to print 'Exception ignored ... TRRReader has no attribute _xdr' and
    its traceback after the package's one-line error; stderr is now that line alone."""
    trr = tmp_path / "run.trr"
    if content is not None:
        trr.write_bytes(content)
    run = subprocess.run([sys.executable, "-c", SCRIPT, "observe", datafiles.PRM_NCBOX, str(trr)],
                         capture_output=True, text=True, timeout=120, env=dict(os.environ, PYTHONWARNINGS="ignore"))
    lines = [line for line in run.stderr.splitlines() if line.strip()]
    assert run.returncode == 2 and len(lines) == 1, run.stderr
    assert lines[0].startswith(f"symprk observe: error: MDAnalysis cannot read {datafiles.PRM_NCBOX} with {trr}: ")


def test_a_dt_that_contradicts_the_stored_times_is_refused(files, capsys):
    """Before: --dt replaced the file's times without a word: it joined the 0.5 ps not written between two files
    (D computed across the gap), and --dt 0.02 on frames 0.01 ps apart halved D and doubled the times.  Now a
    --dt is checked against the times a file stores; one that agrees is taken, one that contradicts them is
    refused naming both."""
    assert main([files.pdb, str(files.a), str(files.b), "--dt", "0.01", "--progress", "never"]) == 2
    err, out = _err_line(capsys)
    assert ("--dt 0.01 contradicts the times the file stores: between frame 99 (t = 0.99 ps) and frame 100 "
            "(t = 1.5 ps) 0.51 ps pass, where --dt puts 0.01 ps: --dt cannot join a stretch of the run that was not "
            "written; analyse one evenly spaced piece with --start/--stop (the longest: --start 0 --stop 100)") in err
    assert out == ""
    assert main([files.pdb, str(files.a), "--dt", "0.02", "--progress", "never"]) == 2
    err, out = _err_line(capsys)
    assert ("--dt 0.02 contradicts the times the file stores: between frame 0 (t = 0 ps) and frame 1 (t = 0.01 ps) "
            "0.01 ps pass, where --dt puts 0.02 ps (99 of the 99 steps so): the file's frames are 0.01 ps apart; "
            "drop --dt") in err and out == ""
    # with --step the stored steps span several frames: --dt is still the interval between the file's frames
    assert main([files.pdb, str(files.a), "--dt", "0.02", "--step", "2"]) == 2
    assert "between frame 0 (t = 0 ps) and frame 2 (t = 0.02 ps) 0.02 ps pass, where --dt puts 0.04 ps" in \
        _err_line(capsys)[0]
    # a --dt that agrees with the stored times is taken
    assert main([files.pdb, str(files.a), "--dt", "0.01", "--step", "2", "--progress", "never"]) == 0
    assert "50 frames every 0.02 ps (--dt)" in capsys.readouterr().out


def test_dt_joins_files_whose_clock_starts_again_and_says_so(files, capsys):
    """The DCD twice: the second file's clock starts again (t = 6 ps, then 0.01 ps).  Without --dt that is
    refused (time goes back); --dt 0.01 says the frames follow each other, which the header repeats."""
    argv = [files.pdb, files.dcd, files.dcd, "--start", "550", "--stop", "650", "--progress", "never"]
    assert main(argv) == 2
    assert "time goes back by 5.99 ps" in _err_line(capsys)[0]
    assert main(argv + ["--dt", "0.01"]) == 0
    assert "100 frames every 0.01 ps (--dt; the file's clock starts again at frame 600)" in capsys.readouterr().out


@pytest.mark.parametrize("step", ["-1", "0"])
def test_a_step_that_is_not_a_positive_integer_is_refused_by_name(files, step, capsys):
    """Before: --step -1 read the frames backwards and was refused as frames '... nan ps apart'."""
    assert main([files.pdb, files.dcd, "--step", step]) == 2
    err, out = _err_line(capsys)
    assert err.endswith(f"--step must be a positive integer (read every step-th frame: 1 reads them all), got {step}")
    assert out == ""


@pytest.mark.parametrize("which", ["trajectory", "topology", "a link to the topology"])
def test_json_naming_an_input_file_is_refused_and_the_file_kept(files, which, tmp_path, capsys):
    """Before: --json naming the trajectory (or the topology) replaced it with the JSON, exit 0."""
    pdb, dcd = tmp_path / "water.pdb", tmp_path / "water.dcd"
    pdb.write_bytes(open(files.pdb, "rb").read())
    dcd.write_bytes(open(files.dcd, "rb").read())
    before = {p: p.read_bytes() for p in (pdb, dcd)}
    target = {"trajectory": dcd, "topology": pdb, "a link to the topology": tmp_path / "obs.json"}[which]
    if which.startswith("a link"):
        target.symlink_to(pdb)
    assert main([str(pdb), str(dcd), "--stop", "20", "--json", str(target)]) == 2
    err, out = _err_line(capsys)
    what = "trajectory" if which == "trajectory" else "topology"
    assert f"--json {target} is the {what}" in err and "that symprk observe reads" in err and out == ""
    assert "give another file name (e.g. " in err
    if which.startswith("a link"):
        assert f"({pdb})" in err
    assert {p: p.read_bytes() for p in (pdb, dcd)} == before
