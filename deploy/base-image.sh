#!/usr/bin/env bash
# base-image.sh [IMAGE]: make a Debian 12 (bookworm) base image in podman's
# local storage with debootstrap, from this machine's own apt sources, so that
# `podman build -f deploy/Dockerfile` needs no registry. Does nothing when
# IMAGE (default localhost/debian:12) already exists.
#
# The mirror is read at run time from /etc/apt/sources.list and
# /etc/apt/sources.list.d/*.list|*.sources (deb822): every enabled `deb` entry
# for a bookworm suite (bookworm, bookworm-updates, bookworm-security) whose
# InRelease says "Origin: Debian". debootstrap --variant=minbase installs from
# the `bookworm` entry; the image's /etc/apt/sources.list gets all of them, so
# apt inside the image sees the same package versions as this machine. An apt
# proxy (Acquire::http::Proxy) and Acquire::Check-Valid-Until "false" are
# carried over when this machine's apt is configured with them.
#
# Needs root (debootstrap), debootstrap, python3 and podman. Honours
# CONTAINERS_CONF / CONTAINERS_STORAGE_CONF, so deploy/smoke.sh can aim it at
# its private storage.
#
# Exit status: 0 the image exists; 1 failure; 77 cannot be made here (not
# root, a tool missing, no Debian bookworm entry in the apt sources, the
# mirror unreachable), with the reason on stdout.
set -euo pipefail

image=${1:-localhost/debian:12}
skip() { echo "SKIP: $*"; exit 77; }

command -v podman >/dev/null || skip "podman is not installed"
if podman image exists "$image"; then
  echo "base-image: $image already present"
  exit 0
fi
[ "$(id -u)" -eq 0 ] || skip "making $image with debootstrap needs root (running as uid $(id -u))"
command -v debootstrap >/dev/null || skip "debootstrap is not installed (scripts/setup.sh installs it)"
command -v python3 >/dev/null || skip "python3 is not installed"

# apt's own proxy setting, for debootstrap (wget) and the probe below.
if [ -z "${http_proxy:-}" ]; then
  proxy=""
  eval "$(apt-config shell proxy Acquire::http::Proxy)"
  if [ -n "$proxy" ] && [ "$proxy" != DIRECT ]; then export http_proxy=$proxy; fi
fi

# "URI SUITE COMPONENT..." for every Debian bookworm entry of this machine's apt sources.
entries=$(python3 - <<'EOF'
import glob, re, sys, urllib.request

def one_line(path):
    for line in open(path, encoding="utf-8", errors="replace"):
        line = line.split("#", 1)[0].strip()
        if not line.startswith("deb "):
            continue
        line = re.sub(r"\[[^\]]*\]", " ", line[4:])   # drop [ options ]
        words = line.split()
        if len(words) >= 3:
            yield words[0], words[1], words[2:]

def deb822(path):
    text = open(path, encoding="utf-8", errors="replace").read()
    for stanza in re.split(r"\n\s*\n", text):
        fields, key = {}, None
        for line in stanza.splitlines():
            if line.startswith("#"):
                continue
            if line[:1] in (" ", "\t") and key:
                fields[key] += " " + line.strip()
            elif ":" in line:
                key, value = line.split(":", 1)
                key = key.strip().lower()
                fields[key] = value.strip()
        if "deb" not in fields.get("types", "").split():
            continue
        if fields.get("enabled", "yes").lower() == "no":
            continue
        for uri in fields.get("uris", "").split():
            for suite in fields.get("suites", "").split():
                yield uri, suite, fields.get("components", "main").split()

found = []
for path in ["/etc/apt/sources.list"] + sorted(glob.glob("/etc/apt/sources.list.d/*.list")):
    try:
        found += one_line(path)
    except OSError:
        pass
for path in sorted(glob.glob("/etc/apt/sources.list.d/*.sources")):
    found += deb822(path)

seen = set()
for uri, suite, components in found:
    if not re.fullmatch(r"bookworm(-[a-z]+)?", suite) or (uri, suite) in seen:
        continue
    seen.add((uri, suite))
    url = uri.rstrip("/") + "/dists/" + suite + "/InRelease"
    try:
        with urllib.request.urlopen(url, timeout=20) as r:
            head = r.read(4096).decode("utf-8", "replace")
    except Exception as e:
        print(f"base-image: {url}: {e}", file=sys.stderr)
        continue
    if re.search(r"^Origin: Debian$", head, re.M):
        print(uri, suite, " ".join(components))
EOF
)
mirror=$(awk '$2 == "bookworm" { print $1; exit }' <<<"$entries")
[ -n "$mirror" ] || skip "no reachable Debian 'bookworm' entry in this machine's apt sources"

root=$(mktemp -d "${TMPDIR:-/tmp}/vrl-debootstrap.XXXXXX")
trap 'rm -rf -- "$root"' EXIT
echo "base-image: debootstrap --variant=minbase bookworm from $mirror"
debootstrap --variant=minbase --components=main bookworm "$root" "$mirror" > "$root.log" 2>&1 || {
  tail -n 30 "$root.log"; rm -f "$root.log"; echo "base-image: debootstrap failed" >&2; exit 1; }
rm -f "$root.log"

awk '{ printf "deb %s %s", $1, $2; for (i = 3; i <= NF; i++) printf " %s", $i; print "" }' <<<"$entries" \
  > "$root/etc/apt/sources.list"
valid_until=""
eval "$(apt-config shell valid_until Acquire::Check-Valid-Until)"
{
  echo "// Carried over from the machine that made this image (deploy/base-image.sh)."
  [ -n "${http_proxy:-}" ] && echo "Acquire::http::Proxy \"$http_proxy\";"
  [ "$valid_until" = false ] && echo 'Acquire::Check-Valid-Until "false";'
  true
} > "$root/etc/apt/apt.conf.d/90vrl-base-image"
rm -rf "$root"/var/lib/apt/lists/* "$root"/var/cache/apt/*.bin "$root"/var/cache/apt/archives/*.deb

tar --numeric-owner --xattrs -C "$root" -c . |
  podman import --quiet --change 'CMD ["/bin/bash"]' --message "debootstrap --variant=minbase bookworm" - "$image" >/dev/null
echo "base-image: made $image ($(podman image inspect --format '{{.Size}}' "$image") bytes)"
