#!/usr/bin/env bash
# runtime-packages.sh BINARY...: the Debian packages that hold every shared
# library BINARY... load, one name per line, sorted.
#
# The libraries come from ldd (the whole closure, so a library's own
# dependencies are listed too) and each resolved path is mapped to its package
# with dpkg-query -S. Run it where the binaries were built: the image's build
# stage (deploy/Dockerfile) or, for deploy/smoke.sh's runtime-only image, a
# Debian 12 host with the -dev packages of scripts/setup.sh. The runtime stage
# installs exactly this list (`xargs apt-get install`), so it follows the link
# line instead of a hand-kept list.
#
# Exits 1, naming the library, when ldd cannot resolve a library or no package
# owns it (e.g. a library under /usr/local: it could not be installed by apt).
set -euo pipefail

if [ $# -eq 0 ]; then
  echo "usage: $0 BINARY..." >&2
  exit 1
fi

ldd_out=$(ldd "$@")
if grep -q 'not found' <<<"$ldd_out"; then
  echo "runtime-packages: ldd cannot resolve:" >&2
  grep 'not found' <<<"$ldd_out" >&2
  exit 1
fi
# "libx.so.1 => /path (0x...)" and the loader's "/path (0x...)"; linux-vdso has no file.
mapfile -t libs < <(awk '$2 == "=>" && $3 ~ /^\// { print $3 } $1 ~ /^\// && $2 ~ /^\(0x/ { print $1 }' <<<"$ldd_out" | sort -u)

# With merged /usr, ldd reports /lib/... where the package ships /usr/lib/...
# (or the other way round), and a soname link may point elsewhere: ask dpkg
# about each spelling of each path (no subshell per library: there are ~300).
mapfile -t reals < <(readlink -f "${libs[@]}")
spellings=()   # spellings of libs[i]: 4 entries from 4*i
for i in "${!libs[@]}"; do
  for p in "${libs[$i]}" "${reals[$i]}"; do
    case $p in
      /usr/*) spellings+=("$p" "${p#/usr}") ;;
      *) spellings+=("$p" "/usr$p") ;;
    esac
  done
done
declare -A owner=()
# "pkg1:arch, pkg2:arch: /path"; paths nobody owns only go to stderr.
while IFS= read -r line; do
  owner[${line##*: }]=${line%: *}
done < <(dpkg-query -S $(printf '%s\n' "${spellings[@]}" | sort -u) 2>/dev/null | grep -v '^diversion by ' || true)

arch=$(dpkg --print-architecture)
found=()
missing=0
for i in "${!libs[@]}"; do
  pkgs=""
  for p in "${spellings[@]:$((4 * i)):4}"; do
    if [ -n "${owner[$p]:-}" ]; then pkgs=${owner[$p]}; break; fi
  done
  if [ -z "$pkgs" ]; then
    echo "runtime-packages: no Debian package owns ${libs[$i]}" >&2
    missing=1
  else
    found+=("$pkgs")
  fi
done
[ "$missing" -eq 0 ] || exit 1
printf '%s\n' "${found[@]}" | tr ',' '\n' | sed -e 's/^ *//' -e "s/:$arch\$//" | sort -u
