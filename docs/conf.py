"""Sphinx configuration of the documentation site: the pages are docs/*.md (MyST), the API reference is generated
from the docstrings of every module of openmm_symprk (autodoc, with an autosummary table per module).

    pip install -e ".[docs]" && sphinx-build -W -n -b html docs docs/_build/html

(README's "Documentation site"; .ci/run runs that command as README spells it.)
``-n`` (nitpicky) makes every reference that points at no documented name a warning, and ``-W`` makes warnings
errors.  There is no network for intersphinx, so names of other packages (numpy, OpenMM, MDAnalysis, the standard
library) are ignored by ``nitpick_ignore_regex``; names of this package are never ignored.
"""
import enum
import importlib
import logging as std_logging
import inspect
import os
import pkgutil
import re
import sys

from sphinx.domains.python import PythonDomain
from sphinx.ext.napoleon import Config as NapoleonConfig
from sphinx.ext.napoleon.docstring import NumpyDocstring
from sphinx.util import logging
from sphinx.util.nodes import make_refnode

_LOG = logging.getLogger("openmm_symprk.docs")
std_logging.getLogger("MDAnalysis").setLevel(std_logging.ERROR)  # its import-time notes are not the site's warnings
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))  # document the checkout, whatever is installed

project = "openmm_symprk"
author = "the openmm_symprk developers"

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "data"]  # data: studies' committed results (docs/data/fidelity), not pages

# -- the pages (MyST) --------------------------------------------------------------------------------------
#: Markdown headings up to this level get GitHub-style anchors, so that links such as thermostat.md#api work.
myst_heading_anchors = 4

# -- the API reference -------------------------------------------------------------------------------------
PACKAGE = "openmm_symprk"
#: Where the API pages are written (one per module, at every build; not kept in git).
API_DIR = "_api"
#: Modules that are build outputs, not the package's source: the SWIG wrapper of the native plugin (its Python
#: face is :class:`openmm_symprk.integrators.native_backend.NativeSymplecticIntegrator`).
API_SKIP = re.compile(r"openmm_symprk\.plugin\.symprk_swig.*")
autosummary_generate = False  # the module pages are written by _write_api_pages; autosummary draws their tables
autodoc_default_options = {"members": True, "show-inheritance": True, "ignore-module-all": True}
autodoc_member_order = "bysource"
autodoc_typehints = "signature"
#: The few docstrings with NumPy-style sections ("Parameters" underlined with dashes) are read by napoleon's
#: parser (see _numpy_sections); parameter types stay the prose they are written as ("time Quantity or float
#: (ps)"), not cross-references.
NAPOLEON = NapoleonConfig(napoleon_google_docstring=False, napoleon_numpy_docstring=True, napoleon_use_param=False,
                          napoleon_use_rtype=False, napoleon_preprocess_types=False)

# -- references --------------------------------------------------------------------------------------------
nitpicky = True
#: The packages the API points at that this site does not document (no intersphinx without network).  Only
#: external names: a reference to an openmm_symprk name that does not exist must stay an error.
_EXTERNAL = r"(openmm|mm|app|unit|simtk|numpy|np|scipy|MDAnalysis|mda|matplotlib|plt|pymbar|tqdm|dask|distributed|" \
            r"collections|concurrent|dataclasses|enum|os|pathlib|typing|numbers|fractions|argparse|json|io|abc|re|" \
            r"subprocess|multiprocessing|warnings|types|logging|hashlib|contextlib|itertools|functools|Fraction|" \
            r"datetime|sys|ctypes|threading|queue|random|array|tomllib|csv|textwrap|inspect|builtins)"
nitpick_ignore_regex = [
    (r"py:.*", _EXTERNAL + r"(\..*)?"),
    # builtins and typing names, as they appear in signatures and numpy-style parameter types
    (r"py:.*", r"(int|float|complex|str|bytes|bool|object|list|tuple|dict|set|frozenset|type|callable|None|"
               r"Callable|Iterable|Iterator|Sequence|Mapping|Any|Optional|Union|Literal|ndarray|array_like|"
               r"optional|Exception|ValueError|TypeError|KeyError|RuntimeError|UserWarning|Warning|"
               r"NotImplementedError|OSError|ImportError|ArithmeticError|LookupError)"),
]


def _modules():
    """Every module of the package, packages before their modules, in name order (build outputs left out)."""
    pkg = importlib.import_module(PACKAGE)
    names = [PACKAGE] + [m.name for m in pkgutil.walk_packages(pkg.__path__, PACKAGE + ".", onerror=lambda name: None)]
    return sorted(n for n in names if not API_SKIP.fullmatch(n) and not any(p.startswith("_") for p in n.split(".")))


def _defined_here(module):
    """The public classes and functions a module defines (not those it imports), in source order."""
    found = []
    for name, obj in vars(module).items():
        if name.startswith("_") or not (inspect.isclass(obj) or inspect.isfunction(obj)):
            continue
        if getattr(obj, "__module__", None) == module.__name__:
            found.append(name)
    return found


#: A cross-reference role in RST (its target written relative to the module whose docstring holds it).
_ROLE = re.compile(r":[\w:]+:`(~?)([^`<]+)`")


#: Per module: the lines that follow its docstring on its page (its submodules, and a table of what it defines).
_SUMMARIES = {}


def _write_api_pages(app):
    """One page per module: its docstring, its submodules, a table of the classes and functions it defines, and
    their docstrings (autodoc).  Written here, not by autosummary's recursive mode, because that one imports
    ``a.b.c`` as attribute ``c`` of ``a.b``, and in this package a function can share its module's name
    (``openmm_symprk.stats.drift`` is both), which makes it document the function in place of the module."""
    out = os.path.join(app.srcdir, API_DIR)
    os.makedirs(out, exist_ok=True)
    names, modules = [], {}
    for name in _modules():
        try:
            modules[name] = importlib.import_module(name)
            names.append(name)
        except ImportError as exc:  # a warning (an error under -W) that says what to install, not a traceback
            _LOG.warning(f"API reference: {name} does not import ({exc}); pip install -e '.[docs]' installs what every "
                         f"module needs")
    pages = {}
    for name in names:
        module = modules[name]
        title = f"``{name}``"
        lines = [title, "=" * len(title), "", f".. automodule:: {name}", ""]
        summary = []
        children = [n for n in names if n.rpartition(".")[0] == name]
        if children:
            summary += ["", ".. rubric:: Modules", ""]
            for child in children:
                doc = inspect.getdoc(modules[child]) or ""
                first = [doc.split("\n\n")[0].replace("\n", " ").strip()]
                first[0] = _ROLE.sub(lambda m: f"``{m.group(2).lstrip('.')}``", first[0])  # relative to the child
                _norm_bars(app, "module", child, None, None, first)
                first = first[0].removesuffix("::").rstrip(":") + ("." if first[0].endswith("::") else "")
                summary.append(f"* :mod:`{child}`" + (f" -- {first}" if first else ""))
            lines += [".. toctree::", "   :hidden:", ""] + [f"   {c}" for c in children] + [""]
        members = _defined_here(module)
        if members:
            summary += ["", ".. rubric:: Defined here", "", ".. autosummary::", ""] + [f"   {m}" for m in members]
        _SUMMARIES[name] = summary + [""]
        pages[name] = "\n".join(lines)
    for name, text in pages.items():
        path = os.path.join(out, name + ".rst")
        old = open(path, encoding="utf-8").read() if os.path.exists(path) else None
        if old != text:  # unchanged pages keep their time stamp, so that Sphinx does not reread them
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(text)
    for stale in set(os.listdir(out)) - {n + ".rst" for n in pages}:
        os.remove(os.path.join(out, stale))


def _module_summary(app, what, name, obj, options, lines):
    """A module's submodules and the table of what it defines, right after its docstring (before autodoc's
    entries of its members)."""
    if what == "module" and name in _SUMMARIES:
        lines.extend(_SUMMARIES[name])


def _include_undocumented(app, what, name, obj, skip, options):
    """Every public class, function, method and enumeration member is listed, with or without a docstring
    (imported ones are still left to the module that defines them); other undocumented data stays out."""
    if skip and not name.startswith("_") and (inspect.isclass(obj) or inspect.isfunction(obj)
                                               or (what in ("class", "exception") and isinstance(obj, enum.Enum))):
        return False
    return None


_MISSING = object()


def _import(path):
    """The object a dotted path names, importing the longest module prefix (a module shadowed by a function of
    the same name in its package still counts as the module), or _MISSING."""
    parts = path.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for part in parts[i:]:
            obj = getattr(obj, part, _MISSING)
            if obj is _MISSING:
                break
        return obj
    return _MISSING


def _resolve_existing(app, env, node, contnode):
    """A reference to a name of this package that exists under the path it is written with but is documented
    under another: a name a package re-exports (``openmm_symprk.SymplecticIntegrator``, documented in
    ``openmm_symprk.integrators.symplectic``), or written relative to the module it appears in (``drift.Drift``
    in ``openmm_symprk.stats``).  The name is imported, and the reference goes to where its object is documented;
    a name that does not import, or whose object is not documented, stays a warning."""
    if node.get("refdomain") != "py":
        return None
    target = node["reftarget"].lstrip(".~")
    module = node.get("py:module") or ""
    cls = node.get("py:class")
    parts = module.split(".") if module else []
    candidates = [f"{module}.{cls}.{target}"] if module and cls else []
    candidates += [".".join(parts[:i] + [target]) for i in range(len(parts), 0, -1)] + [target]
    py = env.get_domain("py")
    for path in candidates:
        if not path.startswith(PACKAGE):
            continue
        obj = _import(path)
        if obj is _MISSING:
            continue
        if inspect.ismodule(obj):
            canonical = obj.__name__
        elif hasattr(obj, "__qualname__") and hasattr(obj, "__module__"):
            canonical = f"{obj.__module__}.{obj.__qualname__}"
        else:  # data: where the same object is documented under the same name
            last = "." + path.rpartition(".")[2]
            same = [n for n in py.objects if n.endswith(last) and _import(n) is obj]
            canonical = same[0] if len(same) == 1 else path
        entry = py.objects.get(canonical)
        if entry is not None:
            return make_refnode(app.builder, node["refdoc"], entry.docname, entry.node_id, contnode, canonical)
        if any(p.startswith("_") for p in canonical.split(".")):
            return contnode  # a private name: it exists, and is left out of the reference, so it is not a link
        return None
    if module and not cls:  # a summary line of a class, read outside it: a member of exactly one class here
        inside = [n for n in py.objects if n.startswith(module + ".") and n.endswith("." + target)
                  and n.count(".") == module.count(".") + 2]
        if len(inside) == 1:
            entry = py.objects[inside[0]]
            return make_refnode(app.builder, node["refdoc"], entry.docname, entry.node_id, contnode, inside[0])
        mod = _import(module)
        if target.rpartition(".")[2].startswith("_") and inspect.ismodule(mod):
            for c in vars(mod).values():  # a private member of a class of this module: it exists, undocumented
                if inspect.isclass(c) and _import(f"{c.__module__}.{c.__qualname__}.{target}") is not _MISSING:
                    return contnode
    return None


class _RelativePythonDomain(PythonDomain):
    """Python's domain, where a ``.name`` reference is looked up as Python's relative import reads it.

    Sphinx reads ``.name`` as "in this module or class, else anything whose dotted name ends so": ``.scenes``
    ends both ``openmm_symprk.systems.scenes`` and ``openmm_symprk.studies.drift.scenes`` (ambiguous), and a
    stale ``.rows`` silently links to whichever module of that name exists somewhere.  Here the module's
    package and its parents come before that suffix search, and a reference found only by the suffix search is
    a warning: it names nothing at the place it is written."""

    def find_obj(self, env, modname, classname, name, type, searchmode=0):
        if searchmode != 1 or not modname or not name.removesuffix("()"):
            return super().find_obj(env, modname, classname, name, type, searchmode)
        bare = name.removesuffix("()")
        objtypes = list(self.object_types) if type is None else self.objtypes_for_role(type) or []
        parts = modname.split(".")
        exact = ([f"{modname}.{classname}.{bare}"] if classname else []) + [f"{modname}.{bare}", bare]
        exact += [".".join(parts[:i] + [bare]) for i in range(len(parts) - 1, 0, -1)]
        for full in exact:
            entry = self.objects.get(full)
            if entry is not None and entry.objtype in objtypes:
                return [(full, entry)]
        matches = super().find_obj(env, modname, classname, name, type, searchmode)
        if matches:
            _LOG.warning(f"reference {name!r} in {modname} is found only by Sphinx's suffix search "
                         f"({', '.join(m[0] for m in matches)}): write it relative to the module's package or in full")
        return matches


def _public_bases(app, name, obj, options, bases):
    """Show a class's documented bases: a private base, or one of a module left out (API_SKIP), is replaced by its
    own bases."""
    i = 0
    while i < len(bases):
        if getattr(bases[i], "__name__", "").startswith("_") or API_SKIP.fullmatch(getattr(bases[i], "__module__", "")):
            bases[i:i + 1] = [b for b in bases[i].__bases__ if b is not object]
        else:
            i += 1


#: ``|x|`` in this package's docstrings is an absolute value or a norm (|dL|/|L|), never an RST substitution.
_BARS = re.compile(r"(?<![\\|])\|(?=[^\s|])([^|\n]*?[^\s|\\])\|(?!\|)")
#: Inline literals and roles, inside which nothing is escaped.
_LITERALS = re.compile(r"(``.+?``|:[\w:]+:`[^`]*`|`[^`]*`_?)")


def _norm_bars(app, what, name, obj, options, lines):
    """Escape |x| (a norm, in the docstrings' plain-text convention) outside literals, so that RST does not read
    it as a substitution reference."""
    for i, line in enumerate(lines):
        if "|" in line:
            parts = _LITERALS.split(line)
            parts[::2] = [_BARS.sub(r"\\|\1\\|", p) for p in parts[::2]]
            lines[i] = "".join(parts)


_UNDERLINE = re.compile(r"\s*-{3,}\s*")


def _numpy_sections(app, what, name, obj, options, lines):
    """Napoleon's NumPy-style parsing, for the docstrings of modules, classes and functions that have a section
    underlined with dashes.  Not as the sphinx.ext.napoleon extension: that one also rewrites every attribute's
    ``#:`` comment, reading "The demo's rows, in order: (label, ...)" as a type and its description."""
    if what in ("attribute", "data", "property") or not any(_UNDERLINE.fullmatch(line) for line in lines):
        return
    lines[:] = NumpyDocstring(lines, NAPOLEON, None, what, name, obj, options).lines()


def setup(app):
    app.add_domain(_RelativePythonDomain, override=True)
    app.connect("builder-inited", _write_api_pages)
    app.connect("autodoc-skip-member", _include_undocumented)
    app.connect("autodoc-process-bases", _public_bases)
    app.connect("missing-reference", _resolve_existing)
    app.connect("autodoc-process-docstring", _numpy_sections)
    app.connect("autodoc-process-docstring", _norm_bars)
    app.connect("autodoc-process-docstring", _module_summary)


# -- output ------------------------------------------------------------------------------------------------
html_theme = "furo"
html_title = "openmm_symprk"
