"""The docstrings' examples run, and the package ships its types."""

import doctest
from pathlib import Path

import pytest

import rwt
import rwt._analyse
import rwt._sample
import rwt._stipple


@pytest.mark.parametrize("module", [rwt._sample, rwt._stipple, rwt._analyse])
def test_docstring_examples(module):
    result = doctest.testmod(module)
    assert result.attempted > 0 and result.failed == 0


def test_typed_package():
    here = Path(rwt.__file__).parent
    assert (here / "py.typed").is_file() and (here / "_rwt.pyi").is_file()
