"""Posters from Python (``poster=(w, h)``): the drawing is the whole, its
sheets are drawings of their own, and the folder is the CLI's."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import pixelpie

ROOT = Path(__file__).resolve().parents[2]
ASSETS = ROOT / "assets"
CLI = Path(os.environ.get("PIXELPIE_BIN", ROOT / "target" / "release" / "pixelpie"))

OPTIONS = dict(poster=(500, 300), paper="a4", margin=10, points=6000, pen_mm=0.3, seed=2)


@pytest.fixture(scope="module")
def poster(tmp_path_factory):
    out = tmp_path_factory.mktemp("py") / "poster"
    return pixelpie.stipple(ASSETS / "rocket.jpg", output=out, **OPTIONS), out


def test_a_poster_returns_the_whole_and_its_sheets(poster):
    d, _ = poster
    m = d.poster
    assert m is not None and len(d.sheets) == len(m["sheets"]) == m["rows"] * m["cols"] > 1
    # Every dot of the whole on exactly one sheet, at its place on the
    # poster (the whole's page is the frame) within 0.02 mm.
    fx, fy, fw, fh = m["frame_mm"]
    whole = d.to_mm(d.dots) + [fx, fy]
    placed = []
    for sheet, entry in zip(d.sheets, m["sheets"]):
        assert sheet.page == (210.0, 297.0)
        assert len(sheet.dots) == entry["dots"] > 0
        assert entry["plot_minutes"] > 0
        mm = sheet.to_mm(sheet.dots) + [entry["x_mm"], entry["y_mm"]]
        placed.append(mm)
        inside = sheet.to_mm(sheet.dots)
        assert (inside >= 10 - 1e-6).all() and (inside <= [200 + 1e-6, 287 + 1e-6]).all()
    placed = np.concatenate(placed)
    assert len(placed) == len(whole)
    key = lambda a: a[np.lexsort((a[:, 1], a[:, 0]))]  # noqa: E731
    assert np.abs(key(placed) - key(whole)).max() < 0.02
    # The whole is at the poster's frame.
    assert abs(d.page[0] - fw) < 1e-6 and abs(d.page[1] - fh) < 1e-6


def test_the_folder_is_the_clis(poster, tmp_path):
    d, out = poster
    cli = tmp_path / "cli"
    args = ["stipple", str(ASSETS / "rocket.jpg"), "-o", f"{cli}/", "--poster", "500x300",
            "--paper", "a4", "--margin", "10", "--points", "6000", "--pen-mm", "0.3",
            "--seed", "2", "-q"]
    subprocess.run([str(CLI), *args], check=True)
    files = sorted(p.name for p in out.iterdir())
    assert files == sorted(p.name for p in cli.iterdir())
    assert "poster.json" in files and len(files) == len(d.sheets) + 1
    for name in files:
        if name.endswith(".svg"):
            assert (out / name).read_bytes() == (cli / name).read_bytes(), name
    # save() writes the same folder.
    again = tmp_path / "again"
    d.save(again)
    assert sorted(p.name for p in again.iterdir()) == files
    assert json.loads((again / "poster.json").read_text())["sheets"] == json.loads(
        (out / "poster.json").read_text())["sheets"]


def test_bad_posters_say_what_to_change(tmp_path):
    taken = tmp_path / "taken.svg"
    taken.write_text("x")
    with pytest.raises(ValueError, match="folder"):
        pixelpie.stipple(ASSETS / "rocket.jpg", output=taken, **OPTIONS)
    assert taken.read_text() == "x"
    with pytest.raises(ValueError, match="paper"):
        pixelpie.stipple(ASSETS / "rocket.jpg", poster=(500, 300), points=500)
    with pytest.raises(TypeError, match="poster"):
        pixelpie.stipple(ASSETS / "rocket.jpg", poster=500, paper="a4", points=500)
    plain = pixelpie.stipple(ASSETS / "rocket.jpg", points=500)
    assert plain.sheets == [] and plain.poster is None
