#!/usr/bin/env python3
"""Checks that every external command the tests and scripts run comes from a Debian package that
scripts/install-deps.sh names, from one of those packages' dependencies, or from a package every Debian system has
(Essential, or Priority required: what `debootstrap --variant=minbase` installs).

Why: a green run on a well-stocked machine hid a missing install step once (issue 45: cpack's dpkg-shlibdeps needs
`file`, which install-deps.sh did not name, so the test command failed on a bare Debian 12). Here a command counts
when the machine running the check has it, so the check fails on the machine that would otherwise hide the gap.

The commands: the words in command position of the shell scripts the test command and CI run (the first word of a
line or after | && || ; $( ` then do else, the word after exec, xargs, timeout N, env, nohup, command), the programs
CMake looks for (find_program NAMES), the browser the viewer tests drive, and the commands other programs run for
us (INDIRECT: cpack's Debian generator runs file, dpkg-shlibdeps and dpkg-deb). Words that are not commands on this
machine (shell keywords, functions, our own tools) are skipped; a command found only outside Debian's folders
(/usr/local, ~/.pyenv) is not one a package provides and is reported too.

Usage: scripts/check-commands.py [--without PACKAGE ...]   (--without drops packages from install-deps.sh's list:
the test shows the check fails when `file` is left out). Exit 0 when every command is covered, 1 otherwise.
"""

import argparse
import os
import pathlib
import re
import shlex
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
DEBIAN_PATH = "/usr/sbin:/usr/bin:/sbin:/bin"
SHELL_FILES = ["scripts/*.sh", ".ci/run", "tests/cli/*.sh", "tests/cli/lib/*.sh", "tests/layers/*.sh"]
CMAKE_FILES = ["CMakeLists.txt", "cmake/*.cmake", "viewer/viewer.cmake", "python/CMakeLists.txt",
               "bench/CMakeLists.txt", "fuzz/CMakeLists.txt"]
# Commands run by programs we call, not by our files (CMake's Modules/Internal/CPack/CPackDeb.cmake).
INDIRECT = {"cpack": ["file", "dpkg-shlibdeps", "dpkg-deb"]}
# The viewer's browser tests start Debian's Chromium by path (tests/viewer/lib.mjs).
EXTRA = ["chromium"]
BEFORE_COMMAND = {"|", "||", "&&", ";", "then", "do", "else", "elif", "if", "while", "until", "!", "(", "{", "exec",
                  "xargs", "env", "nohup", "command", "time", "sudo", "$(", "`"}
SHELL_WORDS = {"if", "then", "else", "elif", "fi", "for", "while", "until", "do", "done", "case", "esac", "in",
               "function", "select", "return", "local", "export", "declare", "readonly", "set", "shift", "trap",
               "cd", "source", ".", "eval", "exit", "wait", "read", "printf", "echo", "true", "false", "test", "[",
               "[[", "]]", "unset", "break", "continue", "let", "type", "hash", "ulimit", "umask", "kill", "pwd"}


def install_deps_packages():
    """What the test command and CI install: install-deps.sh's own list with --clients, --format and --fuzz."""
    out = subprocess.run(["bash", str(ROOT / "scripts" / "install-deps.sh"), "--list", "--clients", "--format",
                          "--fuzz"], capture_output=True, text=True, check=True).stdout
    return set(out.split()) | {"npm"}  # named unless an npm is already there (NodeSource's nodejs brings its own)


def dependency_closure(packages):
    """The packages and, recursively, everything they depend on (every alternative of an `a | b`), as apt sees it."""
    out = subprocess.run(["apt-cache", "depends", "--recurse", "--no-recommends", "--no-suggests", "--no-conflicts",
                          "--no-breaks", "--no-replaces", "--no-enhances", *sorted(packages)],
                         capture_output=True, text=True, check=True).stdout
    closure = set(packages)
    for line in out.splitlines():
        word = line.split(":", 1)[-1].strip().strip("<>") if ":" in line else line.strip().strip("<>")
        if word:
            closure.add(word.split(":")[0])
    return closure


def base_system_packages():
    out = subprocess.run(["dpkg-query", "-W", "-f", "${Package} ${Essential} ${Priority}\n"], capture_output=True,
                         text=True, check=True).stdout
    return {f[0] for f in map(str.split, out.splitlines()) if len(f) >= 3 and (f[1] == "yes" or f[2] == "required")}


def shell_commands(text):
    words = set()
    for line in text.splitlines():
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        line = re.sub(r"\s#.*$", "", line).replace("$(", " $( ").replace("`", " ` ")
        try:
            tokens = shlex.split(line, posix=True)
        except ValueError:
            tokens = line.split()
        expect, after_timeout = True, False  # the first word of a line is in command position
        for tok in tokens:
            if after_timeout:  # timeout's options and duration come before its command
                if not tok.startswith("-"):
                    after_timeout, expect = False, True
                continue
            if expect and re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*=.*", tok):
                continue  # VAR=value before a command
            if expect and re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.+-]*", tok):
                words.add(tok)
            after_timeout = expect and tok == "timeout"
            expect = tok in BEFORE_COMMAND
    return words


def cmake_programs(text):
    words = set()
    for args in re.findall(r"find_program\(([^)]*)\)", text):
        parts = args.split()
        names = parts[parts.index("NAMES") + 1:] if "NAMES" in parts else parts[1:2]
        words.update(n for n in names if re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.+-]*", n))
    return words


def candidate_commands():
    commands = set(EXTRA)
    for pattern in SHELL_FILES:
        for path in sorted(ROOT.glob(pattern)):
            commands |= shell_commands(path.read_text())
    for pattern in CMAKE_FILES:
        for path in sorted(ROOT.glob(pattern)):
            commands |= cmake_programs(path.read_text())
    for program, needs in INDIRECT.items():
        if program in commands:
            commands.update(needs)
    return commands - SHELL_WORDS


def which(command, path):
    for folder in path.split(":"):
        full = os.path.join(folder, command)
        if os.path.isfile(full) and os.access(full, os.X_OK):
            return full
    return None


def owning_package(path):
    # /usr/bin/awk -> /etc/alternatives/awk -> /usr/bin/mawk: the package owns the end of the chain, while usrmerge
    # means dpkg may know a file under /bin or /usr/bin only by the other name.
    candidates = [path, os.path.realpath(path)]
    for c in list(candidates):
        if c.startswith("/usr/"):
            candidates.append(c[4:])
        else:
            candidates.append("/usr" + c)
    for c in candidates:
        out = subprocess.run(["dpkg", "-S", c], capture_output=True, text=True)
        if out.returncode == 0:
            return {p.strip().split(":")[0] for p in out.stdout.split(":", 1)[0].split(",")}
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--without", nargs="*", default=[], help="packages to drop from install-deps.sh's list")
    args = parser.parse_args()
    named = install_deps_packages() - set(args.without)
    covered = dependency_closure(named) | base_system_packages()
    problems, checked = [], 0
    for command in sorted(candidate_commands()):
        local = which(command, os.environ.get("PATH", DEBIAN_PATH))
        path = which(command, DEBIAN_PATH)
        if path is None:
            if local is not None and not local.startswith(str(ROOT)):
                problems.append(f"{command}: {local} is not in a Debian package's folder ({DEBIAN_PATH})")
            continue  # not a command here (a word of a message, our own tool)
        owners = owning_package(path)
        checked += 1
        if owners is None:
            problems.append(f"{command}: {path} belongs to no Debian package")
        elif not owners & covered:
            problems.append(f"{command}: {path} comes from {', '.join(sorted(owners))}, which "
                            "scripts/install-deps.sh does not install (nor any package it names depends on it)")
    for p in problems:
        print(f"check-commands: {p}", file=sys.stderr)
    print(f"check-commands: {checked} commands checked, {len(problems)} not covered", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
