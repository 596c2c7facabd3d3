"""The README's Python example runs as written (in a scratch folder holding the repository's scenes/), and
docs/python.md's examples too."""

import os
import re
import warnings

import pytest

from conftest import ROOT

import numpy as np


def python_blocks(path, after=None):
    text = path.read_text()
    if after:
        text = text[text.index(after):]
    return re.findall(r"```python\n(.*?)```", text, re.S)


def run_block(code, tmp_path, monkeypatch):
    (tmp_path / "scenes").symlink_to(ROOT / "scenes")
    monkeypatch.chdir(tmp_path)
    scope = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the binvox example warns on purpose
        exec(compile(code, "example", "exec"), scope)
    return scope


def test_readme_example(tmp_path, monkeypatch):
    blocks = python_blocks(ROOT / "README.md", after="## Python")
    assert blocks
    scope = run_block(blocks[0], tmp_path, monkeypatch)
    assert scope["grid"].dims == (128, 127, 99)
    assert (tmp_path / "out" / "bunny.binvox").stat().st_size > 0 and (tmp_path / "out" / "bunny.png").stat().st_size > 0
    assert not (tmp_path / "bunny.binvox").exists()  # nothing outside out/, which .gitignore covers
    assert list(scope["prim"] >= 0) == [True, True, False]
    assert scope["image"].shape == (400, 400, 3)


@pytest.mark.parametrize("index", range(len(python_blocks(ROOT / "docs" / "python.md"))))
def test_docs_examples(tmp_path, monkeypatch, index):
    run_block(python_blocks(ROOT / "docs" / "python.md")[index], tmp_path, monkeypatch)
