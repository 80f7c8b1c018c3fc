"""Line drawings (``style="line"``): one continuous pen line per pen, TSP
art, from Python.

* The drawing draws no dots: it behaves as its line's points
  (``Drawing.line``), one :class:`pixelpie.Stroke` per pen.
* ``paths()`` is one polyline per layer whose points are the line's, in
  order, in mm (the SVG's own path, to its 0.01 mm); with ``refill_mm`` the
  line's parts, each starting where the one before ended; with
  ``line_smooth`` the curves through the points.
* ``plan()`` says the line's width and the count its pen needs.
* Bad settings are refused in Python's words (``style=``, ``line_smooth=``),
  and the count warning names ``points=`` and ``pen_mm=``.

Small drawings: rocket.jpg 60 mm wide with a 0.8 mm pen, about 3000 points.
"""

from __future__ import annotations

import copy
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import pixelpie

ROOT = Path(__file__).resolve().parents[2]
ASSETS = ROOT / "assets"
ROCKET = ASSETS / "rocket.jpg"
#: A line drawing quick to make: about 3000 points.
LINE = dict(style="line", width_mm=60.0, pen_mm=0.8, seed=2)

#: A command-line flag: two dashes and a letter.
FLAG = re.compile(r"--[A-Za-z]")


@pytest.fixture(scope="module")
def line():
    return pixelpie.stipple(ROCKET, **LINE)


def svg_paths(svg: bytes) -> list:
    """Each ``<path d="Mx yldx dy...">`` of a pixelpie pen SVG, layer by
    layer, as an (K, 2) array of mm (the paths are in hundredths of a mm)."""
    text = svg.decode()
    layers = re.split(r'<g inkscape:groupmode="layer"', text)[1:]
    out = []
    for layer in layers:
        found = []
        for d in re.findall(r'<path d="([^"]*)"', layer):
            m = re.fullmatch(r"M([-0-9 ]+)l([-0-9 ]+)", d)
            assert m, f"not a polyline: {d[:80]}"
            numbers = [float(v) for v in re.findall(r"-?[0-9]+", m.group(1) + " " + m.group(2))]
            found.append(np.cumsum(np.array(numbers).reshape(-1, 2), axis=0) * 0.01)
        out.append(found)
    return out


def test_a_line_drawing_draws_no_dots_and_behaves_as_its_line(line):
    assert line.style == "line" and line.plan["style"] == "line"
    assert line.dots.shape == (0, 3)
    (stroke,) = line.strokes
    assert isinstance(stroke, pixelpie.Stroke) and not stroke.smooth
    # The line's points: what len() counts, what reached says, the array.
    n = len(stroke.points)
    assert n > 1000
    assert len(line) == line.reached == n and line.shape == (n, 2)
    assert np.array_equal(np.asarray(line), stroke.points) and np.array_equal(line.line, stroke.points)
    assert np.array_equal(line[:, 0], stroke.points[:, 0])
    # Inside the domain, in domain pixels.
    w, h = line.domain
    assert line.line[:, 0].min() >= 0 and line.line[:, 0].max() <= w
    assert line.line[:, 1].min() >= 0 and line.line[:, 1].max() <= h
    # The pen's width in domain pixels: 0.8 mm at the page's scale.
    (scale, _, _), _ = line._native.transform()
    assert stroke.width * scale == pytest.approx(0.8, rel=1e-4)
    # Read-only: the files are made from the library's drawing.
    with pytest.raises(ValueError, match="read-only"):
        line.line[0, 0] = 1.0
    with pytest.raises(ValueError, match="read-only"):
        stroke.points[0, 0] = 1.0
    assert repr(line).startswith(f"<pixelpie.Drawing: a line through {n} points")
    # A copy is the same drawing.
    c = copy.copy(line)
    assert np.array_equal(c.line, line.line) and c.style == "line" and c.svg() == line.svg()


def test_a_drawing_of_dots_has_no_line():
    d = pixelpie.stipple(ROCKET, points=300)
    assert d.style == "dots" and d.strokes == [] and d.line.shape == (0, 2)
    assert len(d) == len(d.dots) == d.reached > 0


def test_paths_are_one_polyline_per_layer_through_the_lines_points_in_order(line):
    layers = line.paths()
    assert len(layers) == 1
    (layer,) = layers
    assert layer.pen_mm == 0.8 and layer.colour == "#000000"
    (path,) = layer.paths
    # The line's points, in order, in mm on the page: no per-dot paths.
    assert path.shape == (len(line), 2)
    assert np.allclose(path, line.to_mm(line.line), rtol=0, atol=1e-9)
    # The SVG's one path is the same polyline, to its 0.01 mm.
    (svg_layer,) = svg_paths(line.svg())
    (svg_path,) = svg_layer
    assert svg_path.shape == path.shape
    assert np.abs(svg_path - path).max() <= 0.0051
    # One continuous line: every step shorter than the drawing.
    steps = np.hypot(*np.diff(path, axis=0).T)
    assert steps.max() < 60 and steps.sum() > 1000


def test_a_refilled_line_is_cut_into_parts_that_start_where_the_last_ended(line):
    d = pixelpie.stipple(ROCKET, **LINE, refill_mm=400.0)
    assert np.array_equal(d.line, line.line)
    layers = d.paths()
    n = len(layers)
    assert n > 2
    assert [layer.name for layer in layers] == [f"{k} black {k}/{n}" for k in range(1, n + 1)]
    parts = []
    for layer in layers:
        (part,) = layer.paths  # one path per layer
        length = np.hypot(*np.diff(part, axis=0).T).sum()
        assert length <= 400.0 + 1e-6
        parts.append(part)
    for before, after in zip(parts, parts[1:]):
        assert np.allclose(after[0], before[-1], rtol=0, atol=1e-9)
    # Together, the whole line: each part's first point is the last one's
    # end (a cut inside a segment adds that point).
    whole = np.concatenate([parts[0]] + [p[1:] for p in parts[1:]])
    full = line.paths()[0].paths[0]
    assert np.hypot(*np.diff(whole, axis=0).T).sum() == pytest.approx(
        np.hypot(*np.diff(full, axis=0).T).sum(), rel=1e-9)
    # Every point of the line is on the cut line, in order.
    kept = [i for i, p in enumerate(whole) if np.any(np.all(np.abs(full - p) < 1e-9, axis=1))]
    assert len(kept) >= len(full)
    # The SVG's layers are these parts.
    got = svg_paths(d.svg())
    assert [len(g) for g in got] == [1] * n
    for g, part in zip(got, parts):
        assert g[0].shape == part.shape and np.abs(g[0] - part).max() <= 0.0051


def test_a_smooth_line_curves_through_its_points_in_order():
    d = pixelpie.stipple(ROCKET, **LINE, line_smooth=True)
    (stroke,) = d.strokes
    assert stroke.smooth and np.array_equal(d.line, stroke.points)
    (layer,) = d.paths()
    (path,) = layer.paths  # still one path
    vertices = d.to_mm(d.line)
    assert len(path) > len(vertices)
    # The curve passes through each point, in the line's order.
    at = 0
    for v in vertices:
        hits = np.flatnonzero(np.all(np.abs(path[at:] - v) < 1e-6, axis=1))
        assert hits.size, f"the curve misses {v} after point {at}"
        at += int(hits[0])
    # Its file holds curves, not a polyline.
    assert re.search(r'<path d="M[-0-9 ]+c', d.svg().decode())


def test_colour_lines_are_one_line_per_pen_and_per_layer():
    d = pixelpie.stipple(ROCKET, **LINE, pens="cmyk")
    assert d.pens is not None and len(d.strokes) == len(d.pens) == 4
    assert d.dots.shape == (0, 4)
    # The line's points with their pen, each pen's line after the last.
    assert d.line.shape == (d.reached, 3) == (sum(len(s.points) for s in d.strokes), 3)
    pens = d.line[:, 2].astype(int)
    assert np.array_equal(pens, np.repeat(np.arange(4), [len(s.points) for s in d.strokes]))
    for k, s in enumerate(d.strokes):
        assert np.array_equal(d.line[pens == k, :2], s.points)
    assert repr(d).startswith("<pixelpie.Drawing: 4 lines through")
    # One path per layer, the pen's line, the lightest ink first.
    layers = d.paths()
    assert [layer.name for layer in layers] == ["yellow", "cyan", "magenta", "black"]
    names = [p.name for p in d.pens]
    for layer in layers:
        (path,) = layer.paths
        k = names.index(layer.name)
        assert np.allclose(path, d.to_mm(d.strokes[k].points), rtol=0, atol=1e-9)


def test_the_plan_of_a_line_says_its_width_and_the_count_its_pen_needs(line):
    p = pixelpie.plan(ROCKET, **LINE)
    assert p == line.plan
    assert p["style"] == "line" and p["line"].startswith("one line through")
    lp = p["line_plan"]
    assert lp["width_mm"] == pytest.approx(0.8) and lp["width_px"] > 0
    # The count follows from the pen: the plan's, close to what it needs
    # (the correction may recount the line's points for its ink).
    assert p["points"] == line.asked
    assert abs(p["points"] - lp["needed"]) <= 0.1 * lp["needed"]
    assert abs(line.reached - lp["needed"]) <= 0.25 * lp["needed"]
    assert "pen" in lp["why"]
    # A thicker pen needs fewer points.
    thick = pixelpie.plan(ROCKET, **{**LINE, "pen_mm": 1.2})
    assert thick["line_plan"]["needed"] < 0.6 * lp["needed"]
    # A plan of dots has no line's plan.
    dots = pixelpie.plan(ROCKET, points=500)
    assert dots["style"] == "dots" and "line_plan" not in dots
    assert isinstance(dots["line"], str)


def test_without_a_pen_the_count_sets_the_lines_width():
    d = pixelpie.stipple(ROCKET, style="line", points=2000, seed=1)
    lp = d.plan["line_plan"]
    assert lp["width_mm"] is None and "count" in lp["why"]
    assert abs(d.reached - 2000) <= 100
    # No page in mm: no pen paths.
    with pytest.raises(ValueError, match="pen_mm"):
        d.paths()
    # Fewer points, a wider line (against the picture's width).
    fewer = pixelpie.plan(ROCKET, style="line", points=1000)
    assert (fewer["line_plan"]["width_px"] / fewer["domain"][0]
            > 1.3 * lp["width_px"] / d.domain[0])


def _refusal(call) -> BaseException:
    with pytest.raises((ValueError, TypeError)) as e:
        call()
    return e.value


@pytest.mark.parametrize("function", [pixelpie.stipple, pixelpie.plan])
def test_a_bad_style_is_refused_in_pythons_words(function):
    e = _refusal(lambda: function(ROCKET, style="bogus", width_mm=60.0, pen_mm=0.8))
    m = str(e)
    assert isinstance(e, ValueError)
    assert "style" in m and "bogus" in m and "line" in m and "dots" in m, m
    assert "\n" not in m and not FLAG.search(m) and "\u00ab" not in m, m


@pytest.mark.parametrize("function", [pixelpie.stipple, pixelpie.plan])
def test_line_smooth_without_a_line_is_refused_naming_both_keywords(function):
    e = _refusal(lambda: function(ROCKET, line_smooth=True, points=300))
    m = str(e)
    assert isinstance(e, ValueError)
    assert "line_smooth" in m and ("style='line'" in m or 'style="line"' in m), m
    assert "\n" not in m and not FLAG.search(m) and "\u00ab" not in m, m
    # The settings stay marked for a front end that names them its own way
    # (the vpype plugin's --line-smooth and --style line).
    raw = getattr(e, "_pixelpie_raw", "")
    assert "\u00abline_smooth\u00bb" in raw and "\u00abstyle=line\u00bb" in raw, raw
    # A bool is True or False.
    e = _refusal(lambda: function(ROCKET, style="line", line_smooth="yes", width_mm=60.0,
                                  pen_mm=0.8))
    assert isinstance(e, TypeError) and "line_smooth" in str(e) and "True or False" in str(e)


def test_a_count_far_from_the_pens_need_warns_with_points_and_pen_mm():
    needed = pixelpie.plan(ROCKET, **LINE)["line_plan"]["needed"]
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        d = pixelpie.stipple(ROCKET, **LINE, points=2 * needed)
    said = [str(w.message) for w in got if issubclass(w.category, pixelpie.PixelpieWarning)]
    assert len(said) == 1, said
    (m,) = said
    assert f"points={2 * needed}" in m and "pen_mm=0.8" in m and "too dark" in m, m
    assert not FLAG.search(m) and "\u00ab" not in m, m
    assert d.warnings == said
    # The count the pen needs warns of nothing.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pixelpie.stipple(ROCKET, **LINE, points=needed)
