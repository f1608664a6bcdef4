"""The README's Python tour runs as written (its printed values are checked in the reference tests)."""

import re
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"


def test_readme_python_blocks_run(capsys):
    text = README.read_text(encoding="utf-8")
    assert text.splitlines()[2].strip() == 'pip install . && crowdvib demo'
    assert text.splitlines()[3].strip() == 'pip install ".[test]" && pytest'
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 2
    namespace = {}
    exec(compile("\n".join(blocks), str(README), "exec"), namespace)
    # The tour's comments promise these values (docs: theory, Reference values).
    assert abs(namespace["occupied"].frequencies[0] - 1.926) < 0.001
    assert abs(namespace["psd"].peak_frequency()[0] - 1.933) < 0.001
    assert abs(namespace["estimate"].msd.frequency - 3.0) < 1e-6
