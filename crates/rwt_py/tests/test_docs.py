"""The docstrings', the READMEs' and the guide's examples run, and the package ships its types."""

import doctest
import re
from pathlib import Path

import pytest

import rwt_noise as rwt
import rwt_noise._analyse
import rwt_noise._sample
import rwt_noise._stipple
import rwt_noise._zoneplate


@pytest.mark.parametrize("module", [rwt._sample, rwt._stipple, rwt._analyse, rwt._zoneplate])
def test_docstring_examples(module):
    result = doctest.testmod(module)
    assert result.attempted > 0 and result.failed == 0


def test_geo_docstring_example():
    pytest.importorskip("geopandas")
    import rwt_noise.geo

    result = doctest.testmod(rwt_noise.geo)
    assert result.attempted > 0 and result.failed == 0


def test_typed_package():
    here = Path(rwt.__file__).parent
    assert (here / "py.typed").is_file() and (here / "_rwt.pyi").is_file()


HERE = Path(__file__).resolve().parent
GUIDE = HERE.parents[2] / "docs" / "guide"
READMES = [HERE.parent / "README.md", HERE.parents[2] / "README.md"] + sorted(
    page for page in GUIDE.glob("*.md") if "```python" in page.read_text()
)


@pytest.mark.parametrize(
    "readme", READMES, ids=["crate", "repository"] + [p.stem for p in READMES[2:]]
)
def test_readme_examples_run(readme, capsys):
    blocks = re.findall(r"```python\n(.*?)```", readme.read_text(), flags=re.S)
    assert blocks, f"{readme} has no python example"
    for block in blocks:
        exec(compile(block, str(readme), "exec"), {})
    assert capsys.readouterr().out.strip(), "the examples print their results"
