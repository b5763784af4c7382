"""compare: run one program with `sicm run` and as the executable `sicm build`
makes of it, and say how the two differ.

Each side runs in an empty directory of its own (the program is given by
absolute path, so diagnostics name the same file), under a time limit that
kills the whole process group. Compared: stdout bytes, the exit status, the
bytes of every file written (plots), and stderr: the same bytes too (a
failure of the executable is laid out as the compiler lays out its
diagnostics: runtime/src/program.c).
"""

from __future__ import annotations

import dataclasses
import os
import signal
import subprocess


@dataclasses.dataclass
class Side:
    status: int | None        # exit status; negative: killed by that signal; None: timed out
    stdout: bytes
    stderr: bytes
    files: dict[str, bytes]


@dataclasses.dataclass
class Outcome:
    kind: str                 # same, difference, build-refused, timeout
    summary: str              # one line: what differs
    run: Side
    built: Side | None        # None when the build failed or timed out
    build_stderr: bytes = b""


def run_process(argv: list[str], cwd: str, limit: float, env: dict[str, str],
                collect_files: bool = True) -> Side:
    """Run argv in cwd; on timeout kill its process group (the C compiler
    that sicm starts, too) and report status None. collect_files: read
    every file the process left in cwd."""
    p = subprocess.Popen(argv, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, start_new_session=True, env=env)
    try:
        out, err = p.communicate(timeout=limit)
        status = p.returncode
    except subprocess.TimeoutExpired:
        try:
            os.killpg(p.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        out, err = p.communicate()
        status = None
    return Side(status, out, err, files_written(cwd) if collect_files else {})


def files_written(d: str) -> dict[str, bytes]:
    out = {}
    for root, _, names in os.walk(d):
        for n in names:
            p = os.path.join(root, n)
            with open(p, "rb") as f:
                out[os.path.relpath(p, d)] = f.read()
    return out


def differing_files(a: dict[str, bytes], b: dict[str, bytes]) -> list[str]:
    """The names written by one side only, else those whose bytes differ."""
    return sorted(set(a) ^ set(b)) or sorted(n for n in a if a[n] != b[n])


def differences(run: Side, built: Side, hide: bytes = b"") -> list[str]:
    """What differs between the two sides, in the order a reader wants it.
    hide: a prefix (the program's directory) left out where text is shown."""
    found = []
    if run.status != built.status:
        found.append(f"exit status: run {run.status}, built {built.status}")
    if run.stdout != built.stdout:
        found.append("stdout" + first_difference(run.stdout, built.stdout))
    run_err, built_err = run.stderr, built.stderr
    if run_err != built_err:
        if hide:
            run_err, built_err = run_err.replace(hide, b""), built_err.replace(hide, b"")
        found.append("stderr" + first_difference(run_err, built_err))
    names = differing_files(run.files, built.files)
    if names:
        found.append("files " + ", ".join(names))
    return found


def first_difference(a: bytes, b: bytes) -> str:
    """': line N: run 'X', built 'Y'' for the first line where a and b differ."""
    la, lb = a.decode(errors="replace").split("\n"), b.decode(errors="replace").split("\n")
    for n, (x, y) in enumerate(zip(la, lb), 1):
        if x != y:
            # From a little before the first character that differs.
            k = next((j for j, (c, d) in enumerate(zip(x, y)) if c != d), min(len(x), len(y)))
            start = max(0, k - 30)
            return f" line {n}: run {x[start:start + 90]!r}, built {y[start:start + 90]!r}"
    n = min(len(la), len(lb)) + 1
    return f" line {n}: run {len(la)} lines, built {len(lb)} lines"


def compare(sicm: str, program_path: str, workdir: str, limit: float,
            env: dict[str, str]) -> Outcome:
    """Run program_path both ways inside workdir (which must be empty)."""
    hide = (os.path.dirname(program_path) + os.sep).encode()
    run_dir, built_dir = os.path.join(workdir, "run"), os.path.join(workdir, "built")
    os.makedirs(run_dir)
    os.makedirs(built_dir)
    run = run_process([sicm, "run", program_path], run_dir, limit, env)
    exe = os.path.join(workdir, "program")
    build = run_process([sicm, "build", program_path, "-o", exe], workdir, limit, env,
                        collect_files=False)
    if run.status is None:
        return Outcome("timeout", f"sicm run timed out after {limit:g} s", run, None,
                       build.stderr)
    if build.status is None:
        return Outcome("timeout", f"sicm build timed out after {limit:g} s", run, None,
                       build.stderr)
    if build.status != 0:
        # An error the program raises while it is compiled is the compiler's
        # to report: it must be the one sicm run reports, with its status.
        # (stdout cannot be compared: the compiler prints none of the
        # program's output.)
        if run.status == 0 or b"error: cannot compile" in build.stderr:
            return Outcome("build-refused", "sicm build refuses a program sicm run runs: " +
                           first_line(build.stderr), run, None, build.stderr)
        as_built = Side(build.status, b"", build.stderr, {})
        found = [d for d in differences(run, as_built, hide) if not d.startswith(("stdout", "files"))]
        if found:
            return Outcome("difference", "at compile time: " + "; ".join(found), run,
                           as_built, build.stderr)
        return Outcome("same", "", run, as_built, build.stderr)
    built = run_process([exe], built_dir, limit, env)
    if built.status is None:
        return Outcome("timeout", f"the executable timed out after {limit:g} s", run, built,
                       build.stderr)
    found = differences(run, built, hide)
    if found:
        return Outcome("difference", "; ".join(found), run, built, build.stderr)
    return Outcome("same", "", run, built, build.stderr)


def first_line(b: bytes) -> str:
    lines = b.decode(errors="replace").strip().split("\n")
    return lines[0][:200] if lines else "(no message)"
