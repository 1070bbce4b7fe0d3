"""The release's files: LICENSE, CITATION.cff (Citation File Format 1.2.0) and CHANGELOG.md agree with the package.

* CITATION.cff parses as YAML, holds the keys CFF 1.2.0 requires (of the file, of each author, of each reference),
  names the package's version and licence, and cites Reich 1994 with its DOI;
* CHANGELOG.md has an entry for the current version, versions newest first;
* LICENSE is the MIT licence with the project's copyright line; README says how to cite.
"""
import os
import re

import pytest

import openmm_symprk

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VERSION = openmm_symprk.__version__
#: CFF 1.2.0: the keys a file must have, and those of an entry of ``references`` / ``preferred-citation``.
CFF_REQUIRED = {"cff-version", "message", "title", "authors"}
REFERENCE_REQUIRED = {"type", "title", "authors"}
#: A person needs family-names (or a name particle/given names); an entity needs name.
PERSON_KEYS = {"family-names", "given-names", "name-particle"}


def _read(name):
    path = os.path.join(REPO, name)
    if not os.path.exists(path):
        pytest.skip(f"{name} is not here (an installed package without its source checkout)")
    with open(path, encoding="utf-8") as fh:
        return fh.read()


@pytest.fixture(scope="module")
def citation():
    yaml = pytest.importorskip("yaml", reason="PyYAML reads CITATION.cff (in the test extra)")
    return yaml.safe_load(_read("CITATION.cff"))


def _check_authors(authors, where):
    assert isinstance(authors, list) and authors, f"{where}: authors must be a non-empty list"
    for author in authors:
        assert isinstance(author, dict), f"{where}: an author is a mapping: {author!r}"
        assert (PERSON_KEYS & set(author)) or "name" in author, f"{where}: an author needs a name: {author}"


def test_citation_has_the_keys_cff_requires(citation):
    assert CFF_REQUIRED <= set(citation), CFF_REQUIRED - set(citation)
    assert citation["cff-version"] == "1.2.0"
    assert isinstance(citation["message"], str) and citation["message"].strip()
    assert citation.get("type", "software") == "software"
    _check_authors(citation["authors"], "CITATION.cff")
    entries = list(citation.get("references", []))
    if "preferred-citation" in citation:
        entries.append(citation["preferred-citation"])
    for entry in entries:
        assert REFERENCE_REQUIRED <= set(entry), (entry.get("title"), REFERENCE_REQUIRED - set(entry))
        _check_authors(entry["authors"], entry["title"])


def test_citation_names_the_package_version_and_licence(citation):
    # a version written unquoted (0.3) would parse as a number: CFF wants a string
    assert citation["version"] == VERSION and isinstance(citation["version"], str)
    assert citation["license"] == "MIT"
    assert "openmm_symprk" in citation["title"]


def test_citation_cites_reich_1994(citation):
    entries = list(citation.get("references", [])) + [citation.get("preferred-citation") or {}]
    reich = [e for e in entries if e.get("doi") == "10.1016/0167-2789(94)90046-9"]
    assert len(reich) == 1, entries
    paper = reich[0]
    assert paper["type"] == "article" and paper["title"] == "Momentum conserving symplectic integrators"
    assert [a.get("family-names") for a in paper["authors"]] == ["Reich"]
    assert (paper["year"], paper["volume"], paper["start"], paper["end"]) == (1994, 76, 375, 383)
    assert "Physica D" in paper["journal"]


def test_changelog_has_an_entry_for_the_current_version():
    text = _read("CHANGELOG.md")
    versions = re.findall(r"^## \[(\d+\.\d+\.\d+)\]", text, re.M)
    assert versions and versions[0] == VERSION, f"CHANGELOG.md's newest entry is {versions[:1]}, the package is {VERSION}"
    key = [tuple(int(x) for x in v.split(".")) for v in versions]
    assert key == sorted(key, reverse=True) and len(set(key)) == len(key), versions
    entry = text.split(f"## [{VERSION}]", 1)[1].split("\n## [", 1)[0]
    assert re.search(r"^- ", entry, re.M), f"the {VERSION} entry lists nothing"


def test_license_is_mit_with_the_copyright_line():
    text = _read("LICENSE")
    assert text.startswith("MIT License\n")
    assert "Copyright (c) 2026 the openmm_symprk developers" in text
    assert "Permission is hereby granted, free of charge" in text


def test_readme_says_how_to_cite():
    readme = _read("README.md")
    section = readme.split("\n## Cite\n", 1)
    assert len(section) == 2, "README.md has no '## Cite' section"
    assert "CITATION.cff" in section[1] and "10.1016/0167-2789(94)90046-9" in section[1]
