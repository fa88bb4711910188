"""``c_build.instance``: a cached library's copy of its own per tag, stored like a build (its bytes recorded),
so that a library whose globals its loader sets can be loaded once per setting."""

import pytest

from stewart_drake.system import c_build


def test_one_copy_per_tag_with_the_librarys_bytes_and_an_altered_copy_replaced(tmp_path, monkeypatch):
    monkeypatch.setenv(c_build.CACHE_ENV, str(tmp_path))
    source = tmp_path / "one.c"
    source.write_text("int sd_one = 1;\n")
    try:
        lib = c_build.build([c_build.Source("one.c", path=source)])
    except c_build.UNAVAILABLE:
        pytest.skip("no C compiler here")
    a, b = c_build.instance(lib, "a"), c_build.instance(lib, "b")
    assert a != b and a.parent == b.parent == lib.parent
    assert a.read_bytes() == b.read_bytes() == lib.read_bytes()
    assert c_build.intact(a) and c_build.intact(b)
    assert c_build.instance(lib, "a") == a
    a.write_bytes(b"truncated")  # a damaged copy is never loaded: it is copied again
    assert c_build.instance(lib, "a") == a and a.read_bytes() == lib.read_bytes()
    # each copy is a file of its own: the loader maps its globals apart from the other's
    ffis = [c_build.load(p, "extern int sd_one;") for p in (a, b)]
    ffis[0][1].sd_one = 7
    assert (ffis[0][1].sd_one, ffis[1][1].sd_one) == (7, 1)
