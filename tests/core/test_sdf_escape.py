"""``core/sdf.escape`` / ``xml_attr``: the same text as ``xml.sax.saxutils.escape`` (the reference it replaces, to
spare every model-writing process that module's imports of urllib.request, http.client and ssl)."""

import subprocess
import sys
from xml.sax.saxutils import escape as sax_escape

import pytest

from stewart_drake.core.sdf import escape, xml_attr, xml_comment

TEXTS = ["a&b<c>d\"e'f", "&amp;", '<<>>&&""', "plain", "--x--", "", "&lt;already&gt;", 'ü & ∑ <tag attr="v">']


@pytest.mark.parametrize("text", TEXTS)
def test_escape_is_saxutils(text):
    assert escape(text) == sax_escape(text)
    assert xml_attr(text) == sax_escape(text, {'"': "&quot;"})
    assert "--" not in xml_comment(text)


def test_sdf_writer_does_not_import_the_network_modules():
    code = "import sys, stewart_drake.core.sdf_models; print(sorted({'urllib.request', 'http.client', 'ssl'} & set(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
