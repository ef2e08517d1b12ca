"""``workbench compile``: the kernels compiled ahead of use, in parallel processes."""
from workbench.model import warmup


def test_every_group_compiles_or_loads_its_kernels():
    result = warmup.compile_all(jobs=2)
    assert [name for name, _, _ in result] == list(warmup.GROUPS)
    assert [error for _, _, error in result] == [""] * len(warmup.GROUPS)


def test_a_failing_group_is_reported_with_its_last_error_line(monkeypatch):
    monkeypatch.setattr(warmup, "GROUPS", {"ok": "x = 1", "broken": "raise ValueError('boom')"})
    result = dict((name, error) for name, _, error in warmup.compile_all(jobs=1))
    assert result == {"ok": "", "broken": "ValueError: boom"}
