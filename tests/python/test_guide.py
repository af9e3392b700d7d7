# SPDX-License-Identifier: Apache-2.0
"""docs/python.md's walk-through runs as written: its python blocks, one after another, from
a folder of their own (the examples are found through sweepers.examples())."""
import os
import re


def test_the_walk_through_runs(monkeypatch, tmp_path):
    source = os.environ["SWEEPERS_SOURCE"]
    guide = open(os.path.join(source, "docs", "python.md")).read()
    blocks = re.findall(r"```python\n(.*?)```", guide, re.S)
    assert len(blocks) >= 6, "the walk-through's blocks were not found"
    monkeypatch.chdir(tmp_path)
    scope = {}
    for block in blocks:
        exec(compile(block, "docs/python.md", "exec"), scope)
    # What the blocks made: a session that replays, a mesh, a plot.
    assert len(scope["s"].script()["strokes"]) == 3
    assert scope["vertices"].shape[1] == 3
    assert os.path.getsize(os.path.join(scope["work"], "convergence.png")) > 10000
    assert set(scope["rows"]["variant"]) == {"corrected", "trilinear"}
