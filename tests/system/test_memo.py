"""``system.memo``: the per-process memo behind the remembered feed-forward tables and loop Diagrams."""

from stewart_drake.system.memo import Memo, digest


def test_memo_computes_once_per_key_and_drops_the_least_recently_used():
    calls = []
    memo = Memo(2)

    def make(name):
        return lambda: calls.append(name) or [name]  # a fresh object per computation

    a, b, c = digest(b"a"), digest(b"b"), digest(b"c")
    first = memo.get(a, make("a"))
    assert memo.get(a, make("a")) is first  # remembered: the same object, not computed again
    memo.get(b, make("b"))
    memo.get(a, make("a"))  # a is now the most recently used
    memo.get(c, make("c"))  # size 2: b goes
    assert memo.get(a, make("a")) is first
    memo.get(b, make("b"))
    assert calls == ["a", "b", "c", "b"]


def test_digest_depends_on_the_order_of_its_parts():
    assert digest(b"x", b"y") != digest(b"y", b"x")
    assert len(digest(b"x")) == 32
