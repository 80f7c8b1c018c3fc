"""The Drawing as a notebook and a script use it: it shows itself in
Jupyter, its dots are read-only (what its files draw), it copies, and a
warning turned into an error leaves no file."""

from __future__ import annotations

import copy
import warnings
from pathlib import Path

import numpy as np
import pytest

import pixelpie

ROOT = Path(__file__).resolve().parents[2]
ASSETS = ROOT / "assets"


@pytest.fixture(scope="module")
def drawing():
    return pixelpie.stipple(ASSETS / "default.png", points=1500, seed=3)


def test_a_drawing_shows_itself_in_jupyter(drawing):
    svg = drawing._repr_svg_()
    assert svg is not None and svg.encode() == drawing.svg()
    assert drawing._repr_png_() is None  # one picture, not two
    big = pixelpie.stipple(ASSETS / "default.png", points=60_000, relax=0,
                           correction="off")
    assert big.reached > pixelpie.Drawing.SVG_REPR_DOTS
    assert big._repr_svg_() is None
    png = big._repr_png_()
    assert png is not None and png == big.png() and png.startswith(b"\x89PNG")


def test_the_dots_are_read_only_so_the_files_cannot_diverge(drawing):
    svg = drawing.svg()
    with pytest.raises(ValueError, match="read-only"):
        drawing.dots[0, 0] = 5.0
    with pytest.raises(ValueError, match="read-only"):
        np.asarray(drawing)[0, 0] = 5.0
    with pytest.raises(AttributeError):
        drawing.dots = np.zeros((3, 3), np.float32)  # type: ignore[misc]
    edited = drawing.dots.copy()
    edited[0, 0] = 5.0
    assert drawing.svg() == svg and drawing.dots[0, 0] != 5.0


@pytest.mark.parametrize("how", [copy.copy, copy.deepcopy])
def test_a_drawing_copies(drawing, how):
    c = how(drawing)
    assert isinstance(c, pixelpie.Drawing) and c is not drawing
    assert np.array_equal(c.dots, drawing.dots) and not c.dots.flags.writeable
    assert c.svg() == drawing.svg() and c.plan == drawing.plan and c.domain == drawing.domain
    assert c.warnings == drawing.warnings and c.stages == drawing.stages


def test_a_warning_made_an_error_leaves_no_file(tmp_path):
    out = tmp_path / "haze.png"
    with warnings.catch_warnings():
        warnings.filterwarnings("error")
        with pytest.raises(pixelpie.PixelpieWarning, match="PNG's dots"):
            pixelpie.stipple(ASSETS / "default.png", out, points=20_000, width=400, scale=0.1)
    assert not out.exists() and list(tmp_path.iterdir()) == []
    # Warned, not raised, the same call writes its file.
    with pytest.warns(pixelpie.PixelpieWarning, match="PNG's dots"):
        d = pixelpie.stipple(ASSETS / "default.png", out, points=20_000, width=400, scale=0.1)
    assert out.read_bytes() == d.png()
