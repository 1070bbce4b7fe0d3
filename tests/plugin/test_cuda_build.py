"""The CUDA kernel library: built, exporting OpenMM's plugin entry points, and linkable against OpenMM's CUDA
platform from PyPI (``pip install "openmm_symprk[cuda12]"``).  Read from the ELF symbol tables (pyelftools),
so no GPU, driver or binutils are needed; running on CUDA is ``symprk gpucheck`` (openmm_symprk.studies.platforms.gpucheck)."""
import os
import sysconfig

import pytest

elftools = pytest.importorskip("elftools", reason="pyelftools (in the 'test' extra) reads the symbol tables")
from elftools.elf.dynamic import DynamicSection  # noqa: E402
from elftools.elf.elffile import ELFFile  # noqa: E402

from openmm_symprk import plugin  # noqa: E402

SYSTEM_DIRS = ["/lib/x86_64-linux-gnu", "/usr/lib/x86_64-linux-gnu", "/lib64", "/usr/lib64", "/lib", "/usr/lib",
               sysconfig.get_config_var("LIBDIR") or "/usr/lib"]


def _cuda_library():
    info = plugin.build_info()
    if "CUDA" not in info.get("libraries", {}):
        pytest.skip(f"the CUDA kernel library was not built: {info.get('skipped', {}).get('CUDA', plugin.unavailable_reason())}")
    return os.path.join(plugin.build_directory(), "lib", info["libraries"]["CUDA"])


def _dynamic(path):
    """(defined symbols, strongly undefined symbols, NEEDED names, RUNPATH folders) of a shared library."""
    with open(path, "rb") as fh:
        elf = ELFFile(fh)
        symtab = elf.get_section_by_name(".dynsym")
        defined, undefined = set(), set()
        for sym in symtab.iter_symbols():
            if not sym.name:
                continue
            if sym["st_shndx"] == "SHN_UNDEF":
                if sym["st_info"]["bind"] != "STB_WEAK":
                    undefined.add(sym.name)
            else:
                defined.add(sym.name)
        needed, runpath = [], []
        for section in elf.iter_sections():
            if isinstance(section, DynamicSection):
                for tag in section.iter_tags():
                    if tag.entry.d_tag == "DT_NEEDED":
                        needed.append(tag.needed)
                    elif tag.entry.d_tag in ("DT_RUNPATH", "DT_RPATH"):
                        origin = os.path.dirname(os.path.abspath(path))
                        runpath += [p.replace("$ORIGIN", origin) for p in (tag.runpath if tag.entry.d_tag == "DT_RUNPATH" else tag.rpath).split(":")]
    return defined, undefined, needed, runpath


def _find(name, folders):
    for d in folders:
        candidate = os.path.join(d, name)
        if os.path.exists(candidate):
            return candidate
    return None


def test_cuda_library_exports_the_plugin_entry_points():
    defined, _, needed, _ = _dynamic(_cuda_library())
    assert {"registerKernelFactories", "registerPlatforms"} <= defined
    assert "libOpenMM.so" in needed and "libOpenMMSymPRK.so" in needed


def test_cuda_library_links_against_openmms_cuda_platform():
    """Every symbol the library leaves undefined resolves in the libraries it names (DT_NEEDED, found through its
    RUNPATH), OpenMM's CUDA platform library among them.  OpenMM loads its platform plugins with dlopen(RTLD_LAZY),
    so their symbols are not global: a library that only relied on libOpenMMCUDA.so being loaded already failed on
    its first call on a GPU ("undefined symbol: _ZN6OpenMM12ComputeArrayC1Ev", seen on an H100)."""
    import openmm.version

    path = _cuda_library()
    cuda_platform = os.path.join(openmm.version.openmm_library_path, "plugins", "libOpenMMCUDA.so")
    _, undefined, needed, runpath = _dynamic(path)
    assert "libOpenMMCUDA.so" in needed, f"the CUDA kernel library does not name OpenMM's CUDA platform: {needed}"
    if not os.path.exists(cuda_platform):
        pytest.skip("OpenMM's CUDA platform is not installed (pip install \"openmm_symprk[cuda12]\")")
    # a named library is found through the RUNPATH (an installed wheel) or, already loaded by `import openmm`, by its
    # soname (an editable install, whose RUNPATH points beside the source tree)
    folders = runpath + [openmm.version.openmm_library_path, os.path.dirname(cuda_platform)] + SYSTEM_DIRS
    assert os.path.samefile(_find("libOpenMMCUDA.so", folders), cuda_platform)
    provided, missing_libraries = set(), []
    for name in needed:
        lib = _find(name, folders)
        if lib is None:
            missing_libraries.append(name)
        else:
            provided |= _dynamic(lib)[0]
    assert not missing_libraries, f"libraries not found: {missing_libraries}"
    unresolved = sorted(s for s in undefined if s not in provided and "@" not in s)
    assert not unresolved, f"{len(unresolved)} symbols resolve nowhere, e.g. {unresolved[:5]}"
    assert any(s.startswith("_ZN6OpenMM12ComputeArray") for s in undefined & _dynamic(cuda_platform)[0]), \
        "expected the Common compute classes to come from the CUDA platform library"
