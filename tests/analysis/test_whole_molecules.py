"""Frames wrapped atom by atom (molecules split across the box, as most engines write them) give the figures of the
same frames wrapped molecule by molecule: ``symprk observe`` and the classes make the molecules whole first.  The
frames are conftest's plain_water (64 SPC/E waters run by OpenMM's VerletIntegrator, positions and velocities in
memory), written here as TRR files with MDAnalysis."""
import json

import numpy as np
import pytest

mda = pytest.importorskip("MDAnalysis")
from MDAnalysis.coordinates.memory import MemoryReader  # noqa: E402

from openmm_symprk.analysis.cli import OBSERVED  # noqa: E402
from openmm_symprk.analysis.universe import KineticTemperatures  # noqa: E402
from openmm_symprk.cli import main as symprk  # noqa: E402

pytestmark = [pytest.mark.filterwarnings("ignore::DeprecationWarning"),
              pytest.mark.filterwarnings("ignore:Reader has no dt"), pytest.mark.filterwarnings("ignore:Found no")]

N_FRAMES = 150  # 1.5 ps, a frame every 10 fs


def _wrapped(p, by_atom: bool):
    """plain_water's first frames (Angstrom) wrapped into the box atom by atom, or molecule by molecule (each
    molecule moved by whole box edges so that its oxygen is in the box)."""
    x, L = 10 * p.x[:N_FRAMES], 10 * p.box
    if by_atom:
        return x - L * np.floor(x / L)
    shift = L * np.floor(x[:, p.molecules[:, 0]] / L)  # (F, n, 3), by each oxygen
    return x - np.repeat(shift, p.molecules.shape[1], axis=1)


def _universe(p, by_atom: bool, bonds: bool = False):
    u = mda.Universe(p.pdb)
    if bonds:
        u.add_TopologyAttr("bonds", [(m[0], m[k]) for m in p.molecules for k in (1, 2)])
    dims = np.tile(np.r_[10 * p.box, 90.0, 90.0, 90.0], (N_FRAMES, 1))
    u.load_new(_wrapped(p, by_atom), format=MemoryReader, dimensions=dims, dt=p.dt,
               velocities=10 * p.v[:N_FRAMES])
    return u


@pytest.fixture(scope="module")
def trr(plain_water, tmp_path_factory):
    """TRR files (positions, velocities, box) of the frames wrapped by atom and by molecule."""
    folder = tmp_path_factory.mktemp("whole")
    out = {}
    for by_atom in (True, False):
        u = _universe(plain_water, by_atom)
        path = folder / f"{'atoms' if by_atom else 'molecules'}.trr"
        with mda.Writer(str(path), u.atoms.n_atoms) as w:
            for _ in u.trajectory:
                w.write(u.atoms)
        out[by_atom] = str(path)
    split = _wrapped(plain_water, True)[:, plain_water.molecules]
    assert (np.linalg.norm(split[:, :, 1:] - split[:, :, :1], axis=3) > 3).any()  # molecules are split
    return out


def test_observe_gives_the_same_figures_for_frames_wrapped_by_atom_and_by_molecule(plain_water, trr, tmp_path,
                                                                                    capsys):
    """Before: T_rot of the frames wrapped atom by atom came from split molecules (their centres of mass and
    inertia wrong) and differed from the molecule-wrapped frames' by tens of K; now every observable agrees."""
    got = {}
    for by_atom, path in trr.items():
        out = tmp_path / f"{by_atom}.json"
        assert symprk(["observe", plain_water.pdb, path, "--json", str(out), "--progress", "never"]) == 0
        got[by_atom] = json.loads(out.read_text())["observables"]
    capsys.readouterr()
    t_rot = got[False]["T_rot"]["value"]
    assert 200 < t_rot < 400 and abs(got[True]["T_rot"]["value"] - t_rot) < 1e-3
    for key, _, _ in OBSERVED:
        a, b = got[True][key], got[False][key]
        assert (a is None) == (b is None), key
        if a is not None:
            assert a["value"] == pytest.approx(b["value"], rel=1e-5, abs=1e-6), key
            assert (a["se"] is None) == (b["se"] is None), key
            if a["se"] is not None:
                assert a["se"] == pytest.approx(b["se"], rel=1e-3, abs=1e-6), key


@pytest.mark.parametrize("bonds", [False, True])
def test_kinetic_temperatures_make_split_molecules_whole(plain_water, bonds):
    """The class on a Universe of frames wrapped atom by atom: without bonds (each site at the minimum image of
    the oxygen) and with them (MDAnalysis' make_whole along the bonds), the temperatures of every frame are
    those of the frames wrapped by molecule, and of the continuous frames in memory."""
    ref = KineticTemperatures(_universe(plain_water, False), by="residues").run().results
    got = KineticTemperatures(_universe(plain_water, True, bonds), by="residues").run().results
    for key in ("translational", "rotational", "internal"):
        np.testing.assert_allclose(got[key], ref[key], rtol=1e-5, atol=1e-6, err_msg=key)
    assert abs(ref.mean_rotational - ref.mean_translational) < 30  # a rigid water's equipartition, roughly
    if bonds:
        frag = KineticTemperatures(_universe(plain_water, True, True), by="fragments").run().results
        np.testing.assert_allclose(frag.rotational, ref.rotational, rtol=1e-5)


def test_a_molecule_without_bonds_too_large_to_make_whole_is_refused():
    """Without bonds a molecule is made whole from its first atom, which holds only for molecules smaller than
    0.4 of the box: a residue reaching farther is refused, asking for bonds."""
    u = mda.Universe.empty(4, n_residues=2, atom_resindex=[0, 0, 1, 1], trajectory=True, velocities=True)
    u.add_TopologyAttr("masses", [16.0, 1.0, 16.0, 1.0])
    u.add_TopologyAttr("resnames", ["BIG", "SMA"])
    u.add_TopologyAttr("resids", [1, 2])
    u.atoms.positions = [[1, 1, 1], [5.5, 1, 1], [3, 3, 3], [3.5, 3, 3]]
    u.atoms.velocities = np.ones((4, 3))
    u.dimensions = [10, 10, 10, 90, 90, 90]
    with pytest.raises(ValueError, match=r"atom 1 lies beyond 0.4 of a box edge from atom 0, the first of the molecule "
                                         r"of atom 0 \(residue BIG 1\): without bonds the molecule cannot be made "
                                         r"whole"):
        KineticTemperatures(u, by="residues").run()
