"""Every message speaks Python: each option of ``stipple`` and ``sample``
given a bad value is refused with a message that names the keyword and no
command-line flag (no ``--width``), with the value as it was given; the
warnings too; and the few messages the trials found wrong say what they
should.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import pixelpie

ROOT = Path(__file__).resolve().parents[2]
ASSETS = ROOT / "assets"

#: A command-line flag: two dashes and a letter.
FLAG = re.compile(r"--[A-Za-z]")

#: A small grey picture, quick to draw.
GREY = (np.add.outer(np.arange(24), np.arange(32)) * 4 % 256).astype(np.uint8)

#: One bad value for each option of ``stipple``.
STIPPLE_BAD = {
    "black_level": 2.0,
    "choose": 0,
    "correction": "bogus",
    "crop": "bogus",
    "dot": "bogus",
    "dot_factor": -1.0,
    "dot_mm": -1.0,
    "dot_path": "bogus",
    "dot_radius": -1.0,
    "dot_ratio": -1.0,
    "exact": "bogus",
    "gamma": -1.0,
    "hdr_white": "bogus",
    "height": 0,
    "ink": "bogus",
    "invert": "bogus",
    "landscape": "bogus",
    "layer_order": "bogus",
    "line_smooth": "bogus",
    "mapping": "bogus",
    "margin": -1.0,
    "max_radius": -1.0,
    "min_radius": -1.0,
    "order": "bogus",
    "paper": "bogus",
    "paper_colour": "bogus",
    "pen_mm": 0,
    "pens": ["bogus"],
    "periodic": "bogus",
    "points": 0,
    "policy": "bogus",
    "poster": "bogus",
    "refill_mm": -1.0,
    "relax": -1,
    "rotate": 45,
    "scale": -1.0,
    "seed": -1,
    "size_px": "bogus",
    "spacing": "bogus",
    "style": "bogus",
    "subpixel_bits": 9,
    "tones": "bogus",
    "white_cutoff": 2.0,
    "white_level": -1.0,
    "width": 0,
    "width_mm": -1.0,
}

#: One bad value for each option of ``sample``.
SAMPLE_BAD = {
    "batch": 0,
    "black_level": 2.0,
    "exact": "bogus",
    "gamma": -1.0,
    "hdr_white": "bogus",
    "height": 0,
    "importance": 5,
    "invert": "bogus",
    "mapping": "bogus",
    "max_iterations": 0,
    "max_radius": -1.0,
    "min_radius": -1.0,
    "periodic": "bogus",
    "points": 0,
    "policy": "bogus",
    "radius": 0.5,
    "radius_map": np.full((8, 8), -3.0),
    "seed": -1,
    "subpixel_bits": 9,
    "tones": "bogus",
    "white_cutoff": 2.0,
    "white_level": -1.0,
    "width": 0,
}

#: The options that shape an importance map: tried with one.
_MAP_OPTIONS = {
    "black_level", "gamma", "hdr_white", "invert", "mapping", "max_radius", "min_radius",
    "tones", "white_cutoff", "white_level",
}


def _refusal(call) -> str:
    """The message of the ValueError or TypeError that ``call`` raises;
    ``""`` when it raises none (the value was taken)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            call()
        except (ValueError, TypeError) as e:
            return str(e)
    return ""


def _fault(name: str, value: object, message: str) -> str | None:
    """What is wrong with ``message``, the refusal of ``name=value``:
    ``None`` when it names the keyword and no flag."""
    if not message:
        return f"{name}={value!r} was taken"
    if FLAG.search(message):
        return f"{name}={value!r} names a flag: {message}"
    if "\u00ab" in message or "\u00bb" in message:
        return f"{name}={value!r} leaves a setting unspelled: {message}"
    # A picture or map names itself in words too ("radius map holds -3 px").
    if name not in message and name.replace("_", " ") not in message:
        return f"{name}={value!r} does not name {name}: {message}"
    return None


def test_the_sweeps_cover_every_option():
    assert set(STIPPLE_BAD) == set(pixelpie.stipple_options())
    assert set(SAMPLE_BAD) == set(pixelpie.sample_options())


#: Refusals whose words come from the library and do not name the option
#: yet: strict, so that the test says when they do.
def _sweep(function: str, bad: dict) -> list:
    return list(bad)


@pytest.mark.parametrize("name", _sweep("stipple", STIPPLE_BAD))
def test_every_stipple_option_refused_names_its_keyword_and_no_flag(name):
    value = STIPPLE_BAD[name]
    options = {"points": 50, name: value} if name != "points" else {name: value}
    message = _refusal(lambda: pixelpie.stipple(GREY, **options))
    assert _fault(name, value, message) is None, _fault(name, value, message)
    # plan() reads the same options and says the same.
    assert _refusal(lambda: pixelpie.plan(GREY, **options)) == message


@pytest.mark.parametrize("name", _sweep("sample", SAMPLE_BAD))
def test_every_sample_option_refused_names_its_keyword_and_no_flag(name):
    value = SAMPLE_BAD[name]
    if name in ("importance", "radius_map") or name in _MAP_OPTIONS:
        options = {"points": 50, name: value}
        if name in _MAP_OPTIONS:
            options["importance"] = GREY
        call = lambda: pixelpie.sample(**options)  # noqa: E731
    elif name in ("points", "radius"):
        call = lambda: pixelpie.sample(32, 32, **{name: value})  # noqa: E731
    else:
        call = lambda: pixelpie.sample(32, 32, radius=2.0, **{name: value})  # noqa: E731
    message = _refusal(call)
    assert _fault(name, value, message) is None, _fault(name, value, message)


def test_the_trials_messages_say_what_they_should():
    def said(call):
        with pytest.raises((ValueError, TypeError)) as e:
            call()
        return str(e.value)

    # The value as given, not as quantized.
    m = said(lambda: pixelpie.sample(radius_map=np.full((8, 8), -3.0)))
    assert "-3" in m and "holds 0 px" not in m, m
    # Each function names itself.
    m = said(lambda: pixelpie.plan(GREY, pionts=5))
    assert m.startswith("plan() got an unexpected option 'pionts'"), m
    m = said(lambda: pixelpie.stipple(GREY, pionts=5))
    assert m.startswith("stipple() got an unexpected option 'pionts'"), m
    # A bool where a count belongs, and a count too large, by name and value.
    with pytest.raises(TypeError) as e:
        pixelpie.sample(32, 32, points=True)
    assert "points" in str(e.value) and "True" in str(e.value), e.value
    with pytest.raises(ValueError) as e:
        pixelpie.sample(32, 32, points=2**70)
    assert f"points={2**70}" in str(e.value), e.value
    # A count too large for its domain, in points as asked, not in the
    # radius found for them.
    m = said(lambda: pixelpie.sample(64, 64, points=1_000_000))
    assert "points=1000000: this domain holds about" in m and "radius=" not in m, m
    # A bool in Python's words.
    m = said(lambda: pixelpie.stipple(GREY, invert="bogus"))
    assert "True or False" in m, m


def test_warnings_name_no_flag(tmp_path):
    # A PNG too coarse for its dots (the trials' "at --scale 0.1").
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        pixelpie.stipple(ASSETS / "default.png", tmp_path / "d.png", points=20_000, width=400,
                         scale=0.1)
    messages = [str(w.message) for w in got]
    assert messages, "the coarse PNG did not warn"
    for m in messages:
        assert not FLAG.search(m) and "\u00ab" not in m, m
