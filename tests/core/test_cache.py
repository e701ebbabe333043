"""The per-user cache folder (core/cache.py): where it is, what clearing it removes."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from truortho.core import cache


def test_env_var_wins(monkeypatch, tmp_path):
    monkeypatch.setenv("TRUORTHO_CACHE_DIR", str(tmp_path / "c"))
    assert cache.cache_root() == tmp_path / "c"
    assert cache.cache_dir("features") == tmp_path / "c" / "features"
    with pytest.raises(ValueError, match="cache kind"):
        cache.cache_dir("products")


@pytest.mark.parametrize(
    ("platform", "env", "expected"),
    [
        ("linux", {"XDG_CACHE_HOME": "/x/cache"}, Path("/x/cache/truortho")),
        ("linux", {}, Path.home() / ".cache" / "truortho"),
        ("darwin", {}, Path.home() / "Library" / "Caches" / "truortho"),
        (
            "win32",
            {"LOCALAPPDATA": "C:/Users/u/AppData/Local"},
            Path("C:/Users/u/AppData/Local/truortho/cache"),
        ),
    ],
)
def test_per_user_default(monkeypatch, platform, env, expected):
    monkeypatch.delenv("TRUORTHO_CACHE_DIR", raising=False)
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)
    for k, v in env.items():
        monkeypatch.setenv(k, v)
    monkeypatch.setattr(sys, "platform", platform)
    assert cache.cache_root() == expected


def test_clear_removes_only_the_caches(monkeypatch, tmp_path):
    monkeypatch.setenv("TRUORTHO_CACHE_DIR", str(tmp_path))
    (tmp_path / "numba" / "m").mkdir(parents=True)
    (tmp_path / "numba" / "m" / "k.nbi").write_bytes(b"x" * 100)
    (tmp_path / "features").mkdir()
    (tmp_path / "features" / "a.npz").write_bytes(b"y" * 50)
    (tmp_path / "notes.txt").write_text("not ours")
    assert cache.cache_size() == 150
    assert cache.clear_cache() == 150
    assert (
        cache.cache_size() == 0 and not (tmp_path / "numba").exists() and not (tmp_path / "features").exists()
    )
    assert (tmp_path / "notes.txt").read_text() == "not ours"


def test_numba_cache_is_in_the_cache_folder():
    import os

    import numba

    from truortho.core import jit  # noqa: F401 - sets the numba cache folder

    assert numba.config.CACHE_DIR == os.environ["NUMBA_CACHE_DIR"]
