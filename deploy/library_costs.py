#!/usr/bin/env python3
"""library_costs.py IMAGE BASE_IMAGE: what each shared library of the vrlcuts
binaries costs in IMAGE, as a Markdown table (deploy/README.md keeps one).

For every library the binaries in /usr/local/bin link directly (DT_NEEDED,
read with LD_DEBUG=files inside the image), the Debian package that holds it
and every package it pulls in through Depends/Pre-Depends, less what
BASE_IMAGE already has. "alone" is the part no other direct library also
needs: what leaving that one library out would save. Sizes are bytes on disk
of each package's regular files in IMAGE (after the image's path-excludes; a
hard-linked file counts once), so they add up to the image's growth over its
base.

Runs podman (as configured by the environment: deploy/smoke.sh --measure sets
CONTAINERS_CONF and friends) and python3 on the host; the image needs only its
own dpkg, ldd and coreutils.
"""

import re
import subprocess
import sys
from collections import defaultdict

BINARIES = ["/usr/local/bin/vrl", "/usr/local/bin/vrl-coordinator", "/usr/local/bin/vrl-worker"]

PROBE = r"""
set -e
bins="%(bins)s"
echo '## status'
dpkg-query -W -f='${Package}\t${Depends}, ${Pre-Depends}\t${Provides}\n'
echo '## files'
dpkg-query -W -f='${Package}\n' | while IFS= read -r p; do dpkg -L "$p" | sed "s|^|$p\t|"; done
echo '## stat'
dpkg-query -W -f='${Package}\n' | xargs dpkg -L | sort -u | xargs -r -d '\n' stat -c '%%F|%%i|%%s|%%n' 2>/dev/null | grep '^regular file|'
echo '## listed'
cat /usr/local/share/vrl/runtime-packages.txt 2>/dev/null || true
echo '## binaries'
stat -c '%%s' $bins
echo '## needed'
for b in $bins; do
  LD_DEBUG=files "$b" --help 2>&1 >/dev/null | sed -n "s|.*file=\([^ ]*\) \[0\];  needed by $b \[0\].*|$b \1|p"
done | sort -u
echo '## ldd'
ldd $bins | awk '$2 == "=>" { print $1, $3 }' | sort -u
echo '## owners'
paths=$(ldd $bins | awk '$2 == "=>" { print $3 }' | sort -u)
for p in $paths; do
  echo "$p"
  case $p in /usr/*) echo "${p#/usr}" ;; *) echo "/usr$p" ;; esac
done | xargs dpkg-query -S 2>/dev/null | grep -v '^diversion by ' || true
"""


def podman(*args):
    return subprocess.run(["podman", *args], check=True, capture_output=True, text=True).stdout


def sections(text):
    out, name = defaultdict(list), None
    for line in text.splitlines():
        if line.startswith("## "):
            name = line[3:].strip()
        elif name and line.strip():
            out[name].append(line)
    return out


def mb(n):
    return f"{n / 1e6:.1f}"


def main(argv):
    if len(argv) != 3:
        print(__doc__.split("\n\n")[0], file=sys.stderr)
        return 1
    image, base = argv[1], argv[2]
    run = ["run", "--rm", "--pull=never", "--network", "none", "--user", "0"]
    probe = sections(podman(*run, image, "sh", "-c", PROBE % {"bins": " ".join(BINARIES)}))
    base_packages = set(podman(*run, base, "dpkg-query", "-W", "-f", "${Package}\n").split())

    depends, providers = {}, defaultdict(set)
    for line in probe["status"]:
        pkg, deps, provides = (line.split("\t") + ["", ""])[:3]
        depends[pkg] = deps
        for v in provides.split(","):
            v = re.sub(r"\(.*?\)", "", v).strip()
            if v:
                providers[v].add(pkg)
    installed = set(depends)

    def edges(pkg):
        for group in depends.get(pkg, "").split(","):
            for alt in group.split("|"):
                name = re.sub(r"\(.*?\)|:\S+", "", alt).strip()
                hit = {name} & installed or providers.get(name, set()) & installed
                if hit:
                    yield from hit
                    break

    def closure(pkg):
        seen, todo = set(), [pkg]
        while todo:
            p = todo.pop()
            if p in seen or p in base_packages:
                continue
            seen.add(p)
            todo.extend(edges(p))
        return seen

    # Bytes on disk of each package's regular files; a file hard-linked under
    # several names (Mesa's DRI drivers) counts once.
    inode_size, path_inode = {}, {}
    for line in probe["stat"]:
        _, inode, n, path = line.split("|", 3)
        inode_size[inode] = int(n)
        path_inode[path] = inode
    size, counted = defaultdict(int), set()
    for line in probe["files"]:
        pkg, path = line.split("\t", 1)
        inode = path_inode.get(path)
        if inode is not None and inode not in counted:
            counted.add(inode)
            size[pkg] += inode_size[inode]
    binaries_size = sum(int(x) for x in probe["binaries"])

    soname_path = dict(line.split(" ", 1) for line in probe["ldd"])
    owner = {}
    for line in probe["owners"]:
        pkgs, path = line.rsplit(": ", 1)
        owner[path] = pkgs.split(",")[0].split(":")[0].strip()
    needed_by = defaultdict(set)
    for line in probe["needed"]:
        binary, soname = line.split(" ", 1)
        needed_by[soname].add(binary.rsplit("/", 1)[1])

    def package_of(soname):
        p = soname_path.get(soname, "")
        for candidate in (p, p[4:] if p.startswith("/usr/") else "/usr" + p):
            if candidate in owner:
                return owner[candidate]
        return "?"

    tops = defaultdict(lambda: {"sonames": set(), "by": set()})
    for soname, by in needed_by.items():
        t = tops[package_of(soname)]
        t["sonames"].add(soname)
        t["by"] |= by
    reach = {pkg: closure(pkg) for pkg in tops}
    count = defaultdict(int)
    for r in reach.values():
        for p in r:
            count[p] += 1
    added = installed - base_packages

    rows = []
    for pkg, t in tops.items():
        alone = {p for p in reach[pkg] if count[p] == 1}
        rows.append((sum(size.get(p, 0) for p in alone), sum(size.get(p, 0) for p in reach[pkg]), pkg, t, alone))
    rows.sort(key=lambda r: (-r[0], r[2]))

    all_bins = {b.rsplit("/", 1)[1] for b in BINARIES}
    print(f"| direct library (package) | needed by | packages it pulls in | MB with them | alone: packages | alone: MB |")
    print("|---|---|---|---|---|---|")
    for alone_size, reach_size, pkg, t, alone in rows:
        by = "all three" if t["by"] == all_bins else ", ".join(sorted(t["by"]))
        names = ", ".join(sorted(t["sonames"]))
        if pkg in base_packages:
            print(f"| {names} ({pkg}) | {by} | base image | 0 | - | 0 |")
            continue
        print(f"| {names} ({pkg}) | {by} | {len(reach[pkg])} | {mb(reach_size)} | {len(alone)} | {mb(alone_size)} |")
    shared = {p for p in added if count[p] > 1}
    unreached = {p for p in added if count[p] == 0}
    total = sum(size.get(p, 0) for p in added)
    print()
    print(f"- packages added to the base image: {len(added)}, {mb(total)} MB on disk "
          f"(shared by two or more direct libraries: {len(shared)}, {mb(sum(size.get(p, 0) for p in shared))} MB"
          + (f"; reached by none: {', '.join(sorted(unreached))}" if unreached else "") + ")")
    print(f"- the three binaries (stripped): {mb(binaries_size)} MB")
    listed = set(probe["listed"])
    if listed:
        extra = sorted(added - listed, key=lambda p: -size.get(p, 0))
        print(f"- installed only because a listed package Depends on them (no file of theirs is in the "
              f"binaries' ldd closure): {len(extra)} packages, {mb(sum(size.get(p, 0) for p in extra))} MB; "
              "largest: " + ", ".join(f"{p} {mb(size.get(p, 0))} MB" for p in extra[:8]))
    biggest = sorted(added, key=lambda p: -size.get(p, 0))[:12]
    print("- largest added packages: " + ", ".join(
        f"{p} {mb(size.get(p, 0))} MB ({'/'.join(sorted(t for t in reach if p in reach[t])) or '-'})" for p in biggest))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
