"""``system.journal``: every line of a resume journal verified, an interrupted last line dropped and cut off before
the next append, a journal of another identity or with a damaged header refused naming the file and line."""

from __future__ import annotations

import json
import re

import pytest

from stewart_drake.errors import JournalError
from stewart_drake.system.journal import JournalWriter, header_line, read_header, read_rows


def _journal(path, identity="k" * 16, rows=3):
    path.write_text(header_line(identity) + "\n")
    w = JournalWriter(path, identity)
    for i in range(rows):
        w.append({"run": i, "value": 0.1 * i})
    w.close()
    return path


def test_rows_read_back_bit_for_bit_with_their_line_numbers(tmp_path):
    path = _journal(tmp_path / "j.jsonl")
    assert read_header(path) == {"key": "k" * 16}
    assert read_rows(path, "k" * 16) == [(2 + i, {"run": i, "value": 0.1 * i}) for i in range(3)]


def test_an_interrupted_last_line_is_left_out_and_cut_before_the_next_append(tmp_path):
    path = _journal(tmp_path / "j.jsonl")
    text = path.read_text()
    path.write_text(text + text.splitlines()[-1][:30])  # a write cut short: no newline
    assert [r["run"] for _, r in read_rows(path, "k" * 16)] == [0, 1, 2]
    w = JournalWriter(path, "k" * 16)
    w.append({"run": 3})
    w.close()
    assert [r["run"] for _, r in read_rows(path, "k" * 16)] == [0, 1, 2, 3]


@pytest.mark.parametrize(
    ("edit", "line"),
    [
        (lambda lines: lines.__setitem__(2, lines[2].replace('"value": 0.1', '"value": 0.2')), 3),
        (lambda lines: lines.__setitem__(slice(1, 3), [lines[2], lines[1]]), 2),  # two rows swapped
        (lambda lines: lines.insert(3, lines[2]), 4),  # a row repeated
        (lambda lines: lines.__setitem__(3, "{}"), 4),  # not a journal line
        (lambda lines: lines.__setitem__(1, lines[1][:9] + "é" + lines[1][10:]), 2),  # a non-ASCII mac
        (lambda lines: lines.__setitem__(1, lines[1][:40]), 2),  # a line cut short, not the last
    ],
)
def test_an_edited_line_is_refused_naming_the_file_and_line(tmp_path, edit, line):
    path = _journal(tmp_path / "j.jsonl")
    lines = path.read_text().splitlines()
    edit(lines)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(JournalError, match=rf"^{re.escape(str(path))}:{line}: does not verify"):
        read_rows(path, "k" * 16)
    with pytest.raises(JournalError, match=rf"^{re.escape(str(path))}:{line}: does not verify"):
        JournalWriter(path, "k" * 16)


def test_another_identity_and_a_damaged_header_are_refused(tmp_path):
    path = _journal(tmp_path / "j.jsonl")
    with pytest.raises(JournalError, match=r":1: a journal of another search or study \(key kkkk"):
        read_rows(path, "m" * 16)
    path.write_text("[1]\n" + "\n".join(path.read_text().splitlines()[1:]) + "\n")
    with pytest.raises(JournalError, match=r":1: not a stewart-drake journal header \('\[1\]'\)"):
        read_rows(path, "k" * 16)
    # the chain starts at the header: the rows of a journal are not valid under another header
    other = _journal(tmp_path / "other.jsonl", identity="k" * 16, rows=0)
    other.write_text(json.dumps({"key": "k" * 16, "extra": 1}) + "\n" + "\n".join(path.read_text().splitlines()[1:]))
    with pytest.raises(JournalError, match=":2: does not verify"):
        read_rows(other, "k" * 16)
