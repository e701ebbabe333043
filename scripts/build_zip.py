"""Build the installable plugin zip: ``dist/truortho-<version>.zip`` with ``truortho/`` at its root.

    python -P scripts/build_zip.py [--output DIR] [--lrelease PATH]

Contents: the files git tracks (or, outside a git checkout, the files of the tree), minus what a
user does not install: tests, benchmarks, developer scripts, CI, tool configuration and every
sample except the demo sample named in ``SAMPLE_KEEP``. Translations (``i18n/*.ts``) are compiled
to ``.qm`` with Qt's ``lrelease`` and added; the ``.ts`` sources stay out. The archive is
deterministic (sorted entries, fixed timestamps), so the same tree gives the same zip.
"""

from __future__ import annotations

import argparse
import fnmatch
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PLUGIN = "truortho"
#: Top-level entries never shipped.
EXCLUDE_TOP = {
    "tests",
    "bench",
    "scripts",
    ".ci",
    ".git",
    ".venv",
    "build",
    "dist",
    "Makefile",
    "pyproject.toml",
    "requirements-bench.txt",
    ".gitignore",
    ".gitattributes",
}
#: Glob patterns never shipped (anywhere); ``.qm`` files are compiled afresh (a tree's own may be stale).
EXCLUDE_GLOBS = ("*.pyc", "*/__pycache__/*", "*.ts", "*.qm", "*.pro", ".*")
#: Sample folders (under sample/) that the zip keeps.
SAMPLE_KEEP = ("copr", "synthetic")
#: Fixed timestamp of every entry (reproducible archives).
TIMESTAMP = (2024, 1, 1, 0, 0, 0)


def version(root: Path = ROOT) -> str:
    for line in (root / "metadata.txt").read_text(encoding="utf-8").splitlines():
        if line.startswith("version="):
            return line.split("=", 1)[1].strip()
    raise SystemExit("build_zip: no version= line in metadata.txt")


def source_files(root: Path = ROOT) -> list[str]:
    """Relative POSIX paths of the files to ship."""
    try:
        out = subprocess.run(["git", "-C", str(root), "ls-files", "-z"], capture_output=True, check=True)
        files = [f for f in out.stdout.decode("utf-8").split("\0") if f]
    except (OSError, subprocess.CalledProcessError):
        files = [p.relative_to(root).as_posix() for p in root.rglob("*") if p.is_file()]
    keep = []
    for f in sorted(files):
        parts = f.split("/")
        if parts[0] in EXCLUDE_TOP:
            continue
        if any(fnmatch.fnmatch(f, g) or fnmatch.fnmatch(parts[-1], g) for g in EXCLUDE_GLOBS):
            continue
        if parts[0] == "sample" and (len(parts) < 3 or parts[1] not in SAMPLE_KEEP):
            continue
        if not (root / f).is_file():  # deleted in the work tree but still tracked
            continue
        keep.append(f)
    return keep


def compile_translations(root: Path, out_dir: Path, lrelease: str | None) -> list[Path]:
    """``i18n/*.ts`` -> ``out_dir/*.qm`` with lrelease; [] when there are no .ts files."""
    sources = sorted((root / "i18n").glob("*.ts"))
    if not sources:
        return []
    tool = lrelease or shutil.which("lrelease") or shutil.which("lrelease-qt5")
    if tool is None and Path("/usr/lib/qt5/bin/lrelease").exists():
        tool = "/usr/lib/qt5/bin/lrelease"
    if tool is None:
        raise SystemExit("build_zip: lrelease not found (Debian: apt-get install qttools5-dev-tools)")
    built = []
    for ts in sources:
        qm = out_dir / (ts.stem + ".qm")
        subprocess.run([tool, "-silent", str(ts), "-qm", str(qm)], check=True)
        built.append(qm)
    return built


def build(output: Path, root: Path = ROOT, lrelease: str | None = None) -> Path:
    output.mkdir(parents=True, exist_ok=True)
    dest = output / f"{PLUGIN}-{version(root)}.zip"
    tmp = dest.with_name(f".{dest.name}.tmp{os.getpid()}")
    with tempfile.TemporaryDirectory() as qm_dir:
        qms = compile_translations(root, Path(qm_dir), lrelease)
        try:
            with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED, compresslevel=9) as zf:
                entries = [(f, root / f) for f in source_files(root)]
                entries += [(f"i18n/{qm.name}", qm) for qm in qms]
                for rel, path in sorted(entries):
                    info = zipfile.ZipInfo(f"{PLUGIN}/{rel}", TIMESTAMP)
                    info.compress_type = zipfile.ZIP_DEFLATED
                    info.external_attr = (0o755 if os.access(path, os.X_OK) else 0o644) << 16
                    zf.writestr(info, path.read_bytes())
            os.replace(tmp, dest)
        finally:
            if tmp.exists():
                tmp.unlink()
    return dest


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--output", default=str(ROOT / "dist"), help="folder for the zip (default dist/)")
    ap.add_argument("--lrelease", default=None, help="path of Qt's lrelease (default: found on PATH)")
    args = ap.parse_args(argv)
    dest = build(Path(args.output), ROOT, args.lrelease)
    with zipfile.ZipFile(dest) as zf:
        n = len(zf.namelist())
    print(f"{dest} ({dest.stat().st_size / 1e6:.1f} MB, {n} files)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
