"""The README's library example runs and says what it claims."""

import re

import numpy as np
from notebook_helpers import ROOT


def test_readme_example_runs_and_its_comments_hold():
    readme = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", readme, re.S)
    example = next(b for b in blocks if "import course_lib" in b)
    namespace: dict = {}
    exec(example, namespace)
    traj = namespace["traj"]
    np.testing.assert_array_equal(traj.y[-1], [-1.375, 0.25])
    assert traj.stable
    assert "array([-1.375, 0.25])" in example
