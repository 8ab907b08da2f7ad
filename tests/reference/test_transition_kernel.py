"""The compiled deviation search, same-way landing and same-way pieces
(reference.transition_kernel) give the vectorised ones' numbers, bit for bit.

The references are :func:`reference.core.transition_sbend._deviation_where`,
:func:`reference.core.transition_samedir._newton` and
:func:`reference.core.transition_samedir._canonical_pieces` themselves, run on the same
inputs:
random S-bends and transitions between arcs curving the same way (the full search, the
sizing's coarse one and the local one ``near`` a place; the landing from either side,
where it lands and where it wanders), every search and landing the sizing makes on the
seeded chains of ``tests/bench/bench_rounding.py``, and the paths built with either.
"""

from __future__ import annotations

import tomllib
from importlib import resources

import numpy as np
import pytest

import reference.core.transition_samedir as samedir
import reference.core.transition_sbend as sbend
import reference.rounding_tangential as tangential
from reference.machine import machine_from_dict
from reference.nc import parse_text
from reference.prepare import build_path
from reference.core.transition import ramp_offset
from reference.transition_kernel import deviation_where, samedir_newton, samedir_pieces
from seeded_programs import s_bend_chain, same_way_chain

PATH_FIELDS = ("origin", "e1", "e2", "d", "radius", "omega", "theta0", "length", "block",
               "kind", "sharpness", "s_breaks")


def _same(a, b) -> None:
    for x, y in zip(a, b, strict=True):
        assert x.dtype == y.dtype and x.shape == y.shape
        assert np.array_equal(x, y, equal_nan=True), np.flatnonzero(x != y)[:10]


def _shapes(kind: str, seed: int, n: int = 300):
    """Pieces, radii and the second centre's canonical ``y`` of ``n`` random transitions
    of ``kind`` ('sbend' or 'samedir') that land."""
    rng = np.random.default_rng(seed)
    r1 = rng.uniform(2.0, 200.0, n)
    r2 = r1 * np.exp(rng.uniform(-3.0, 3.0, n))
    rate = np.exp(rng.uniform(np.log(3.0), np.log(3000.0), n)) / np.minimum(r1, r2) ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        if kind == "sbend":
            sh = sbend.sbend_shape(r1, r2, rate, deviation=False)
        else:
            sh = samedir.samedir_shape(r1, r2, rate, deviation=False)
    ok = np.flatnonzero(np.isfinite(sh.theta))
    assert ok.size > n // 3
    sh = sbend.take(sh, ok)
    pieces_of = sbend._canonical_pieces if kind == "sbend" else samedir._canonical_pieces
    centre = -sh.r_out if kind == "sbend" else sh.r_out
    return pieces_of(sh), sh.r_in, sh.r_out, centre


@pytest.mark.parametrize("kind", ("sbend", "samedir"))
@pytest.mark.parametrize("seed", range(3))
def test_compiled_search_equals_the_vectorised_search(kind, seed):
    pieces, r1, r2, centre = _shapes(kind, seed)
    full = sbend._deviation_where(pieces, r1, r2, centre)
    _same(full, deviation_where(pieces, r1, r2, centre))
    coarse = dict(samples=sbend.LOCATE_SAMPLES, scan=0)
    _same(sbend._deviation_where(pieces, r1, r2, centre, **coarse),
          deviation_where(pieces, r1, r2, centre, **coarse))
    # near: where the full search found its maximum, and elsewhere (other maxima, ends)
    total = pieces[4].sum(axis=1)
    rng = np.random.default_rng(seed)
    inside = []
    for near in (full[1], rng.uniform(-0.1, 1.1, total.size) * total):
        got = deviation_where(pieces, r1, r2, centre, near=near)
        _same(sbend._deviation_where(pieces, r1, r2, centre, near=near), got)
        inside.append(got[2])
    # not vacuous: the compared searches hold maxima inside their window (near the full
    # search's: every one) and outside it (random starts: all but a few of ~300, and
    # some seeds' shapes have none inside, so the two kinds are counted over both)
    inside = np.concatenate(inside)
    assert inside.any() and (~inside).any()


@pytest.mark.parametrize("seed", range(3))
def test_compiled_landing_equals_the_vectorised_landing(seed):
    """Newton's method on the same-way landing from both sides, at radius ratios up to
    e^3.5 (beyond the flatter arc's fold near 16: some wander all NEWTON_MAX_ITER
    steps) and rates from gentle to steep."""
    rng = np.random.default_rng(seed)
    n = 400
    r1 = rng.uniform(2.0, 200.0, n)
    r2 = r1 * np.exp(rng.uniform(-3.5, 3.5, n))
    rate = np.exp(rng.uniform(np.log(2.0), np.log(3000.0), n)) / np.minimum(r1, r2) ** 2
    ramp = 1.0 / (np.minimum(r1, r2) * rate)
    off = (*ramp_offset(r1, ramp)[:2], *ramp_offset(r2, ramp)[:2])
    for side in (r2 > r1, r2 < r1, rng.random(n) < 0.5):
        with np.errstate(invalid="ignore", divide="ignore"):
            want = samedir._newton(r1, r2, ramp, rate, off, side)
        got = samedir_newton(r1, r2, ramp, rate, off, side)
        _same(want, got)
        assert np.isnan(want[0]).any() and np.isfinite(want[0]).any()
        # without the ramps' starts each finds them its own way (the compiled one by
        # its own loop): the same landings
        with np.errstate(invalid="ignore", divide="ignore"):
            _same(want, samedir._newton(r1, r2, ramp, rate, None, side))
        _same(want, samedir_newton(r1, r2, ramp, rate, None, side))


@pytest.mark.parametrize("seed", range(2))
def test_compiled_ramp_starts_equal_ramp_offset(seed):
    """The compiled ramps' starts are ``ramp_offset``'s, bit for bit, from gentle ramps
    (``L/R`` 1e-4) to ramps turning more than a radian."""
    from reference.transition_kernel import _ramp_starts
    rng = np.random.default_rng(20 + seed)
    n = 2000
    r1 = rng.uniform(0.5, 500.0, n)
    r2 = r1 * np.exp(rng.uniform(-3.5, 3.5, n))
    ramp = np.minimum(r1, r2) * np.exp(rng.uniform(np.log(1e-4), np.log(3.0), n))
    want = (*ramp_offset(r1, ramp)[:2], *ramp_offset(r2, ramp)[:2])
    _same(want, _ramp_starts(r1, r2, ramp))


def _samedir_shapes(rng, n: int, log_ratio: float, rate_lo: float):
    """Same-way shapes of ``n`` random transitions: radii 2..200 mm, ratios up to
    ``e^log_ratio`` either way, rates ``rate_lo..3000 / min(R)^2``."""
    r1 = rng.uniform(2.0, 200.0, n)
    r2 = r1 * np.exp(rng.uniform(-log_ratio, log_ratio, n))
    rate = np.exp(rng.uniform(np.log(rate_lo), np.log(3000.0), n)) / np.minimum(r1, r2) ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        return samedir.samedir_shape(r1, r2, rate, deviation=False)


@pytest.mark.parametrize("seed", range(3))
def test_compiled_pieces_equal_the_vectorised_pieces(seed):
    """The same-way pieces of random transitions, those that land and those that do
    not (``theta`` nan: every number nan where the vectorised ones are)."""
    sh = _samedir_shapes(np.random.default_rng(seed), 400, 3.5, 2.0)
    assert np.isnan(sh.theta).any() and np.isfinite(sh.theta).any()
    _same(samedir._canonical_pieces(sh), samedir_pieces(sh))


@pytest.mark.parametrize("seed", range(2))
def test_search_of_packed_pieces_equals_the_vectorised_search(seed):
    """The compiled pieces come packed, as views the compiled search measures as they
    are: its results on them equal the vectorised search's on the vectorised pieces
    (full, coarse and ``near``), and a tuple of other arrays (here copies of those
    views, and views of a packed array whose starts were not filled by the pieces) is
    packed anew, not taken for the one it looks like."""
    from reference.transition_kernel import _packed_of, _views
    rng = np.random.default_rng(10 + seed)
    sh = _samedir_shapes(rng, 300, 3.0, 3.0)
    sh = sbend.take(sh, np.flatnonzero(np.isfinite(sh.theta)))
    views = samedir_pieces(sh)
    assert _packed_of(views) is views[0].base
    copies = tuple(np.array(v) for v in views)
    assert _packed_of(copies) is None
    assert _packed_of(views[:4] + (copies[4],)) is None
    numpy_pieces = samedir._canonical_pieces(sh)
    total = numpy_pieces[4].sum(axis=1)
    for kw in ({}, {"samples": sbend.LOCATE_SAMPLES, "scan": 0},
               {"near": 0.4 * total}):
        want = sbend._deviation_where(numpy_pieces, sh.r_in, sh.r_out, sh.r_out, **kw)
        _same(want, deviation_where(views, sh.r_in, sh.r_out, sh.r_out, **kw))
        _same(want, deviation_where(copies, sh.r_in, sh.r_out, sh.r_out, **kw))
    # views of an array of the same layout whose starts are not the running sum of
    # its lengths are not taken as packed (the search would measure wrong pieces)
    other = rng.uniform(1.0, 2.0, views[0].base.shape)
    assert _packed_of(_views(other)) is None
    other[:, :, 8] = np.cumsum(other[:, :, 7], axis=1) - other[:, :, 7]
    assert _packed_of(_views(other)) is other


def _machine():
    """The default machine with PATH_TRANS_POS_TOL = 0.05 mm (most transitions rounded,
    as in the benchmark)."""
    d = tomllib.loads(resources.files("reference.machines").joinpath("default.toml")
                      .read_text())
    for ax in d["axis"].values():
        ax["PATH_TRANS_POS_TOL"] = 0.05
    return machine_from_dict(d)


PROGRAMS = {"s-bends": s_bend_chain(400, 5), "same-way": same_way_chain(400, 5)}


@pytest.mark.parametrize("name", sorted(PROGRAMS))
def test_every_search_of_the_sizing_and_the_path_are_the_same(monkeypatch, name):
    """Every search and same-way landing the sizing makes (the compiled one run beside
    the vectorised one on the same inputs), and the built path with each alone."""
    prog = parse_text("G17 G90 G645 SOFT F8000\n" + PROGRAMS[name])
    machine = _machine()
    real, real_newton = sbend._deviation_where, samedir._newton
    calls, landings = [], []

    def both(*args, **kw):
        ref = real(*args, **kw)
        _same(ref, deviation_where(*args, **kw))
        calls.append(kw)
        return ref

    def both_newton(*args):
        ref = real_newton(*args)
        _same(ref, samedir_newton(*args))
        landings.append(args[0].size)
        return ref

    with monkeypatch.context() as mp:
        mp.setattr(sbend, "_deviation_where", both)
        mp.setattr(samedir, "_newton", both_newton)
        mp.setattr(tangential, "_compiled_parts", lambda n: (None, None, None))
        plain = build_path(prog, machine)
    assert {"near" in kw for kw in calls} == {False, True} and len(calls) >= 4
    assert (len(landings) >= 4) == (name == "same-way")
    assert int(plain.rounding.inserted.sum()) > 50
    with monkeypatch.context() as mp:
        mp.setattr(tangential, "_compiled_parts",
                   lambda n: (deviation_where, samedir_newton, samedir_pieces))
        fast = build_path(prog, machine)
    for f in PATH_FIELDS:
        assert np.array_equal(getattr(fast, f), getattr(plain, f)), f
