"""Where the tests find the inputs written by others: ``../shared`` beside the repository.

The corpus of NC programs (``corpus/``), the manual excerpts (``manual-excerpts/``), the
result schema (``schema/result.schema.json``) and the model notes the tests cite
(``spec/``, not read by any test) are not part of this repository (``corpus/SOURCES.md``
asks that its programs are used from there and not copied: the ``lcnc_*`` files are
GPL-2.0 data). A fresh clone placed elsewhere has no ``../shared``; every test that reads
from it then skips, naming the file that is absent, rather than failing with
``FileNotFoundError`` or passing without having looked.

This module is the one place that says where ``../shared`` is. Tests import it by name
(``from shared_inputs import corpus_file``): ``tests/conftest.py`` puts ``tests/`` on
``sys.path``; the standalone benchmark scripts in ``tests/bench`` put it there themselves.

Two ways to skip, for the two times a test learns that a file is missing:

* at run time, :func:`shared_file` / :func:`corpus_file` / :func:`excerpt_file` return the
  path or skip the running test;
* at collection time (parametrisation), :data:`CORPUS_PRESENT`, :func:`corpus_listing`,
  :func:`corpus_cases` and :func:`corpus_param` build parameter lists whose corpus cases
  are skipped, with the reason, instead of silently not collected.
"""

from __future__ import annotations

from pathlib import Path

import pytest

#: The repository (this file is ``tests/shared_inputs.py``).
REPO = Path(__file__).resolve().parents[1]
#: The folder of inputs written by others, beside the repository.
SHARED = REPO.parent / "shared"
#: NC programs written by others (both dialects).
CORPUS = SHARED / "corpus"
#: Verbatim excerpts of the control manuals that tests quote.
EXCERPTS = SHARED / "manual-excerpts"
#: DESIGN's JSON schema of a result document (the packaged copy must match it).
SCHEMA = SHARED / "schema" / "result.schema.json"

#: Whether the corpus folder is there (decided once, at import: parametrisation needs it
#: before any test runs).
CORPUS_PRESENT = CORPUS.is_dir()


def absent(path: Path, what: str) -> str:
    """The skip reason for a missing shared input.

    Parameters
    ----------
    path : Path
        The file or folder that is missing (under :data:`SHARED`).
    what : str
        What it is, for the reader of the skip summary.

    Returns
    -------
    str
        ``"../shared/<relative path> not present: <what> (looked in <absolute path>)"``;
        the relative form is what the README names, the absolute one shows where a
        misplaced clone looked.
    """
    try:
        rel = "../shared/" + path.relative_to(SHARED).as_posix()
    except ValueError:          # not under SHARED: name it as it is
        rel = str(path)
    return f"{rel} not present: {what} (looked in {path})"


#: Skip reason of every test that needs the corpus folder.
NO_CORPUS = absent(CORPUS, "the NC programs written by others live beside the "
                           "repository, not in it")

#: What a single corpus file is, in its skip reason.
_CORPUS_PROGRAM = ("a corpus program written by others (the corpus lives beside the "
                   "repository, not in it)")

#: Mark for a test (or, as ``pytestmark``, a module) that needs the corpus folder.
needs_corpus = pytest.mark.skipif(not CORPUS_PRESENT, reason=NO_CORPUS)


def shared_file(path: Path | str, what: str = "an input written by others") -> Path:
    """A file of ``../shared``, or a skip of the running test where it is missing.

    Parameters
    ----------
    path : Path or str
        Absolute, or relative to :data:`SHARED` (``"schema/result.schema.json"``).
    what : str
        What the file is, for the skip reason.

    Returns
    -------
    Path
        The file's absolute path; it exists.

    Raises
    ------
    pytest.skip.Exception
        The file is absent (call this from inside a test, not at import time).
    """
    p = Path(path)
    p = p if p.is_absolute() else SHARED / p
    if not p.is_file():
        pytest.skip(absent(p, what))
    return p


def corpus_file(name: str) -> Path:
    """The corpus program ``name`` (``"lcnc_square.ngc"``), or a skip of the running test.

    Parameters
    ----------
    name : str
        File name inside :data:`CORPUS`.

    Returns
    -------
    Path
        The program's absolute path; it exists.
    """
    return shared_file(CORPUS / name, _CORPUS_PROGRAM)


def excerpt_file(name: str) -> Path:
    """The manual excerpt ``name`` (``"b1-840dsl-dynamic-adaptation.txt"``), or a skip.

    Parameters
    ----------
    name : str
        File name inside :data:`EXCERPTS`.

    Returns
    -------
    Path
        The excerpt's absolute path; it exists.
    """
    return shared_file(EXCERPTS / name, "the manual excerpt this test quotes (the "
                                        "excerpts live beside the repository, not in it)")


def corpus_listing(pattern: str | None = None) -> list[Path]:
    """The entries of the corpus folder, sorted by name; empty where it is absent.

    Each test keeps its own filter on top (suffixes, case): which files it means is part
    of the test.

    Parameters
    ----------
    pattern : str, optional
        A glob pattern (``"*.ngc"``); without it every entry (``Path.iterdir``).

    Returns
    -------
    list of Path
    """
    if not CORPUS_PRESENT:
        return []
    return sorted(CORPUS.glob(pattern) if pattern else CORPUS.iterdir())


def corpus_cases(cases: list, nargs: int = 1) -> list:
    """Parameter cases built from the corpus, or one skipped case saying it is absent.

    An empty parameter list skips with pytest's "got empty parameter set", which does not
    say why, and a list that mixes bundled and corpus programs would silently lose the
    corpus ones; this keeps a visible case with :data:`NO_CORPUS` as its reason.

    Parameters
    ----------
    cases : list
        The cases as the test builds them where the corpus is present.
    nargs : int
        Number of parameter names of the ``parametrize`` (the placeholder's values are
        ``None``; the skip keeps the test body from seeing them).

    Returns
    -------
    list
        ``cases`` where the corpus is present, otherwise ``[pytest.param(None, ...,
        marks=skip(NO_CORPUS), id="corpus-absent")]``.
    """
    if CORPUS_PRESENT:
        return cases
    return [pytest.param(*([None] * nargs), marks=pytest.mark.skip(reason=NO_CORPUS),
                         id="corpus-absent")]


def corpus_param(name: str, value: object = None):
    """One parameter case for the corpus program ``name``, skipped where it is missing.

    Parameters
    ----------
    name : str
        File name inside :data:`CORPUS`; also the case id.
    value : object, optional
        The parameter value; by default the program's :class:`~pathlib.Path`.

    Returns
    -------
    _pytest.mark.ParameterSet
    """
    path = CORPUS / name
    return pytest.param(path if value is None else value, id=name,
                        marks=pytest.mark.skipif(not path.is_file(),
                                                 reason=absent(path, _CORPUS_PROGRAM)))
