#!/usr/bin/env python3
"""check_manifests_test.py REPO_ROOT: check_manifests.py refuses what it must.

Copies deploy/, .dockerignore and CMakeLists.txt of REPO_ROOT into a
temporary tree, checks that the copy passes, then breaks one thing at a time
and expects exit status 1 with the named message:
  * the build stage copies the whole context before compiling (`COPY . .`);
  * a directory CMakeLists.txt adds is not copied before the compile;
  * the runtime stage installs a hand-written package list;
  * .dockerignore lets the coordinator's state or a token through, or is missing;
  * the first stage is not Debian 12.
Prints "N passed, 0 failed"; exits 0 on success, 1 on failure.
"""

import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent


def run_checker(root):
    p = subprocess.run([sys.executable, str(HERE / "check_manifests.py"), str(root)],
                       capture_output=True, text=True)
    return p.returncode, p.stdout + p.stderr


def main(argv):
    if len(argv) != 2:
        print("usage: check_manifests_test.py REPO_ROOT", file=sys.stderr)
        return 1
    repo = Path(argv[1]).resolve()

    def edit(rel, old, new, count=1):
        def apply(root):
            path = root / rel
            text = path.read_text(encoding="utf-8")
            changed, n = re.subn(old, new, text, count=count, flags=re.M)
            if n == 0:
                raise AssertionError(f"{rel}: pattern {old!r} not found (test out of date)")
            path.write_text(changed, encoding="utf-8")
        return apply

    def remove(rel):
        return lambda root: (root / rel).unlink()

    cases = [
        ("whole context copied before the compile",
         edit("deploy/Dockerfile", r"^COPY CMakeLists\.txt \./$", "COPY . ."), "copies the whole context"),
        ("a compiled directory not copied",
         edit("deploy/Dockerfile", r"^COPY render render/?\n", ""), "render/ (add_subdirectory"),
        ("hand-written runtime package list",
         edit("deploy/Dockerfile", r"xargs -a \S+", "apt-get install -y libopenimageio2.4 &&"),
         "hand-listed packages"),
        ("state dir not ignored",
         edit(".dockerignore", r"^\*\*/vrl-state$", ""), "does not exclude 'vrl-state'"),
        ("token not ignored",
         edit(".dockerignore", r"^\*\*/token$", ""), "does not exclude 'deploy/token'"),
        (".dockerignore missing", remove(".dockerignore"), ".dockerignore: missing"),
        ("first stage not Debian 12",
         edit("deploy/Dockerfile", r"^ARG BASE=\S+$", "ARG BASE=ubuntu:22.04"), "first stage must be"),
    ]

    passed = failed = 0
    with tempfile.TemporaryDirectory() as tmp:
        pristine = Path(tmp) / "pristine"
        pristine.mkdir()
        shutil.copytree(repo / "deploy", pristine / "deploy")
        shutil.copy(repo / ".dockerignore", pristine / ".dockerignore")
        shutil.copy(repo / "CMakeLists.txt", pristine / "CMakeLists.txt")
        code, out = run_checker(pristine)
        if code != 0:
            print(f"FAIL: the unmodified copy does not pass:\n{out}")
            return 1
        for i, (name, mutate, expected) in enumerate(cases):
            root = Path(tmp) / f"case{i}"
            shutil.copytree(pristine, root)
            try:
                mutate(root)
            except AssertionError as e:
                print(f"FAIL: {name}: {e}")
                failed += 1
                continue
            code, out = run_checker(root)
            if code == 1 and expected in out:
                passed += 1
            else:
                print(f"FAIL: {name}: exit {code}, expected 1 and {expected!r} in:\n{out}")
                failed += 1
    print(f"{passed} passed, {failed} failed")
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
