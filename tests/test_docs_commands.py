"""Every command in the docs is tested (issue 40 C).

The shell commands of the fenced code blocks of README.md and docs/*.md (``sh``, ``bash``,
``console``, ``shell`` blocks; plain blocks only for lines that start with ``make``, ``snakemake``
or ``python -m netrepro``) are each classified by the first entry of :data:`RULES` that matches:

* ``run``: read-only (a Snakemake dry run, lint, summary or list of changes; ``check-paper``),
  run as written in a scratch copy of the repository, must exit 0;
* ``make``: ``make -n TARGET VARS`` must exit 0 (the target exists and its recipe expands);
* ``help``: a command that writes or names a placeholder paper: ``python -m netrepro SUB --help``
  must exit 0 and name every ``--option`` the docs pass;
* ``skip``: not run, with the reason (it builds, or sets up the shell).

A command no entry matches fails the test: a new form is classified on purpose, in this one list.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from .conftest import ROOT, copy_repo

SHELL_BLOCKS = {"sh", "bash", "console", "shell"}
LEADS = re.compile(r"(make|snakemake|python -m netrepro)\b")
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]

# (regular expression on the command as written, action, reason); the first match wins
RULES = [
    (r"make \S+", "make", "the target exists: make -n"),
    (r"snakemake( --profile \S+)? (-n|--dry-run)( |$)", "run", "a dry run"),
    (r"snakemake (--lint|--list-rules|--help|--summary|--list-changes (params|code|input))$", "run", "read-only"),
    (r"snakemake ", "skip", "builds"),
    (r"python -m netrepro check-paper$", "run", "read-only"),
    (r"python -m netrepro (check-paper|new-paper|register-findings) kalman_iid( |$)", "help",
     "the worked example's placeholder paper (new-paper and register-findings write)"),
    (r"python -m netrepro scale-record ", "help", "writes tests/reference/paper-scale/ from a finished build"),
    (r"python -m pytest tests/papers/kalman_iid$", "skip", "the tests of the worked example's placeholder paper"),
    (r"(source \.venv/bin/activate|export NETREPRO_SLURM_\w+=\S+)$", "skip", "sets up the shell"),
    (r"\.venv/bin/pip install ", "skip", "installs packages"),
    (r"(cp -a|rsync -a|mkdir -p|cd) ", "skip", "copies or moves a checkout (README: Moving and sharing a build)"),
    (r"git (clone|add|commit) ", "skip", "clones or commits"),
]


def _blocks(text):
    """``(language, [(line number, line)])`` of each fenced code block."""
    lang, lines = None, []
    for n, line in enumerate(text.splitlines(), 1):
        stripped = line.strip()
        if stripped.startswith("```"):
            if lang is None:
                lang, lines = (stripped[3:].split() or [""])[0].lower(), []
            else:
                yield lang, lines
                lang = None
        elif lang is not None:
            lines.append((n, line))


def doc_commands(path: Path) -> list[tuple[str, list[str]]]:
    """``(file:line, argv)`` of each shell command in ``path``'s code blocks (comments dropped, ``\\`` joined)."""
    found = []
    for lang, lines in _blocks(path.read_text()):
        if lang not in SHELL_BLOCKS and lang != "":
            continue
        prompt = lang == "console" or any(line.strip().startswith("$ ") for _, line in lines)
        text, first = "", None
        for n, line in lines:
            stripped = line.strip()
            if prompt and not text:
                if not stripped.startswith("$ "):
                    continue  # a console block's output
                stripped = stripped[2:]
            text += (" " if text else "") + stripped.removesuffix("\\").strip()
            first = first or n
            if stripped.endswith("\\"):
                continue
            command, where, text, first = text, f"{path.relative_to(ROOT)}:{first}", "", None
            if not command or command.startswith("#") or (lang == "" and not LEADS.match(command)):
                continue
            found.append((where, shlex.split(command, comments=True)))
    return found


def classify(argv: list[str]) -> tuple[str, str] | None:
    """``(action, reason)`` of the first rule of :data:`RULES` matching the command, or None."""
    written = shlex.join(argv)
    for pattern, action, reason in RULES:
        if re.match(pattern, written):
            return action, reason
    return None


COMMANDS = [c for path in DOCS for c in doc_commands(path)]


def test_the_docs_commands_are_found_and_every_one_is_classified():
    written = {shlex.join(argv) for _, argv in COMMANDS}
    assert {"make report", "make check", "snakemake -n report", "python -m netrepro check-paper kalman_iid"} <= written
    unclassified = [f"{where}: {shlex.join(argv)}" for where, argv in COMMANDS if classify(argv) is None]
    assert not unclassified, "classify these in RULES of tests/test_docs_commands.py:\n" + "\n".join(unclassified)


def test_the_extraction_joins_continuations_and_reads_console_prompts(tmp_path, monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)  # locations are relative to ROOT
    doc = tmp_path / "docs" / "_example_for_the_test.md"
    doc.parent.mkdir()
    doc.write_text("```console\n$ make check   # after make report\nregression: ok\n$ snakemake -n \\\n  report\n```\n"
                   "```\nmake test\nnot a command\n```\n```python\nmake = 1\n```\n")
    assert doc_commands(doc) == [("docs/_example_for_the_test.md:2", ["make", "check"]),
                                 ("docs/_example_for_the_test.md:4", ["snakemake", "-n", "report"]),
                                 ("docs/_example_for_the_test.md:8", ["make", "test"])]
    assert classify(["snakemake", "-n", "-r", "report"]) == ("run", "a dry run")  # run: it fails, as it should
    assert classify(["snakemake", "-j2", "report"])[0] == "skip"
    assert classify(["rm", "-rf", "results"]) is None


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    return copy_repo(tmp_path_factory.mktemp("docs") / "repo")


def _argv(argv: list[str]) -> list[str]:
    """The command with this interpreter for ``python`` and ``snakemake``."""
    if argv[0] == "snakemake":
        return [sys.executable, "-m", "snakemake", *argv[1:]]
    if argv[0] == "python":
        return [sys.executable, *argv[1:]]
    return argv


@pytest.mark.slow  # runs Snakemake (dry runs, summaries, lint) in a scratch copy
@pytest.mark.parametrize("where,argv", [pytest.param(w, a, id=f"{w} {shlex.join(a)}") for w, a in COMMANDS
                                        if (classify(a) or ("",))[0] in ("run", "make", "help")])
def test_a_documented_command_works(where, argv, scratch):
    action, _ = classify(argv)
    env = dict(os.environ, PYTHONPATH=str(scratch / "src"))
    if action == "make":
        variables = [a for a in argv[2:] if "=" in a]
        cmd = ["make", "-n", argv[1], *variables]
    elif action == "help":
        cmd = [sys.executable, "-m", "netrepro", argv[3], "--help"]
    else:
        cmd = _argv(argv)
    proc = subprocess.run(cmd, cwd=scratch, capture_output=True, text=True, timeout=600, env=env)
    assert proc.returncode == 0, f"{where}: {shlex.join(argv)} ({shlex.join(cmd)}) failed:\n{proc.stderr[-3000:]}"
    if action == "help":
        unknown = [a.split("=")[0] for a in argv if a.startswith("--") and a.split("=")[0] not in proc.stdout]
        assert not unknown, f"{where}: options the command does not know: {unknown}"
