"""Benches write their own section of docs/benchmarks.md (issue 20: figures are never hand-copied).

Every bench accepts ``--write-docs`` (``make bench`` passes it): what the bench prints is also
written, as it was printed, between ``<!-- <key>:begin -->`` and ``<!-- <key>:end -->`` of
docs/benchmarks.md, under a line with the command, the commit, the date, the machine and the
versions of the peers it was measured against. A section is replaced only when its bench ends
without an error, so a failed run never leaves half a table.

Every bench ends with::

    if __name__ == "__main__":
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        from _docs import run_main

        sys.exit(run_main(main, "mgcm", "Target detection and least-squares matching", peers=("cv2",)))
"""

from __future__ import annotations

import contextlib
import datetime
import io
import os
import platform
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DOCS = os.path.join(ROOT, "docs", "benchmarks.md")


#: What the benches write (docs sections, pictures): a change there is not a change of the code measured,
#: so it does not make a run "+dirty" (one docs-writing bench after another, before a commit).
WRITTEN_BY_BENCHES = ("docs", "bench/results")


def commit() -> str:
    """Short hash of HEAD (``+dirty`` when the working tree differs outside
    :data:`WRITTEN_BY_BENCHES`), or ``unknown``."""
    try:
        git = ["git", "-C", ROOT]
        rev = subprocess.run([*git, "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
        if rev.returncode != 0:
            return "unknown"
        dirty = subprocess.run(
            [*git, "status", "--porcelain", "--untracked-files=no", "--", ".",
             *(f":(exclude){p}" for p in WRITTEN_BY_BENCHES)],
            capture_output=True,
            text=True,
        )  # fmt: skip
        return rev.stdout.strip() + ("+dirty" if dirty.stdout.strip() else "")
    except OSError:
        return "unknown"


def load_average() -> str:
    """``", load average X at the end"`` where the system has one, else "": a run's times are only
    comparable with another's on an equally idle machine."""
    return f", load average {os.getloadavg()[0]:.1f} at the end" if hasattr(os, "getloadavg") else ""


def shown_argv(argv: list[str], drop: tuple[str, ...] = ()) -> list[str]:
    """A bench's arguments as its docs show them: without ``--keep DIR`` (a local folder, not part
    of what is measured) and without the flags in ``drop``."""
    out = list(argv)
    if "--keep" in out:
        k = out.index("--keep")
        del out[k : k + 2]
    return [a for a in out if not a.startswith("--keep=") and a not in drop]


def measured_commit(started: str | None) -> str:
    """The commit a run measured: ``started`` (:func:`commit` when it started) if given, with a
    remark when HEAD moved during the run; else :func:`commit` now."""
    now = commit()
    if started is None or started == now:
        return now
    return f"{started} (HEAD moved to {now} during the run)"


def header(command: str, peers: dict[str, str] | None = None, started: str | None = None) -> str:
    """The line above a section: command, commit (``started``: see :func:`measured_commit`),
    date, machine, peers."""
    load = load_average()
    peer = "; peers: " + ", ".join(f"{k} {v}" for k, v in peers.items()) if peers else ""
    return (
        f"Command: `{command}` at commit {measured_commit(started)}, {datetime.date.today().isoformat()}, "
        f"{platform.machine()} {os.cpu_count()} cores{load}{peer}."
    )


def write_section(key: str, title: str, lines: list[str], path: str = DOCS) -> None:
    """Replace the text between ``<!-- key:begin -->`` and ``<!-- key:end -->`` of ``path``
    (appended under ``## title`` when missing); written through a temporary file."""
    begin, end = f"<!-- {key}:begin -->", f"<!-- {key}:end -->"
    text = open(path, encoding="utf-8").read() if os.path.exists(path) else "# Benchmarks\n"
    body = "\n".join([begin, *lines, end])
    if begin in text and end in text:
        text = text[: text.index(begin)] + body + text[text.index(end) + len(end) :]
    else:
        marker = "\n## Earlier measurements"
        section = f"## {title}\n\n{body}\n"
        if marker in text:  # keep the hand-recorded history last
            i = text.index(marker)
            text = text[:i].rstrip("\n") + "\n\n" + section + text[i:]
        else:
            text = text.rstrip("\n") + "\n\n" + section
    tmp = path + ".part"
    with open(tmp, "w", encoding="utf-8") as fh:
        fh.write(text)
    os.replace(tmp, path)


class _Tee(io.TextIOBase):
    def __init__(self, stream) -> None:
        self.stream = stream
        self.buffer_text = io.StringIO()

    def write(self, s: str) -> int:
        self.stream.write(s)
        self.buffer_text.write(s)
        return len(s)

    def flush(self) -> None:
        self.stream.flush()


def _version(module: str) -> str | None:
    try:
        mod = __import__(module)
    except Exception:  # noqa: BLE001 - a peer that is not installed is simply not named
        return None
    return str(getattr(mod, "__version__", "?"))


def run_main(main, key: str, title: str, peers: tuple[str, ...] = ()) -> int:
    """Run a bench's ``main()`` with ``--write-docs`` taken off ``sys.argv`` and honoured here:
    what it prints becomes the section ``key`` of docs/benchmarks.md.
    ``peers``: modules whose versions the section names (those importable after the run)."""
    write = "--write-docs" in sys.argv
    sys.argv = [a for a in sys.argv if a != "--write-docs"]
    command = None
    if write:
        name = os.path.splitext(os.path.basename(sys.argv[0]))[0].removeprefix("bench_")
        args = " ".join(sys.argv[1:])
        command = f"make bench BENCH={name}" + (f' BENCH_ARGS="{args}"' if args else "")
    tee = _Tee(sys.stdout) if write else None
    with contextlib.redirect_stdout(tee) if tee is not None else contextlib.nullcontext():
        rc = main()
    rc = int(rc or 0)
    if tee is not None and rc == 0:
        found = {p: v for p in peers if (v := _version(p)) is not None}
        printed = tee.buffer_text.getvalue().rstrip("\n").splitlines()
        write_section(key, title, [header(command or key, found), "", "```text", *printed, "```"])
        print(f"\n(section '{key}' of {os.path.relpath(DOCS, ROOT)} written)")
    return rc
