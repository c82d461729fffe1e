#!/usr/bin/env bash
# runtime_packages_test.sh SOURCE_DIR BINARY...: deploy/runtime-packages.sh,
# which the image's build stage and deploy/smoke.sh use to derive the runtime
# package list from ldd.
#  1. On the binaries just built it exits 0; every name it prints is an
#     installed package; and the package of every library a binary links
#     directly (readelf -d NEEDED, resolved by ldd) is in the list.
#  2. A program whose library ldd cannot find: exit 1, naming the library.
#  3. A program whose library no package owns (found through
#     LD_LIBRARY_PATH): exit 1, naming the library.
# Skips (exit 77) where dpkg, readelf or cc are missing (not Debian).
set -u
src=$1
shift
script=$src/deploy/runtime-packages.sh
for tool in dpkg-query readelf cc; do
  command -v "$tool" >/dev/null || { echo "SKIP: $tool is not installed"; exit 77; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "runtime_packages_test: FAIL: $*"; exit 1; }

# 1. The real binaries.
"$script" "$@" > "$work/list" 2> "$work/err" || fail "exit $? on the built binaries: $(cat "$work/err")"
[ -s "$work/list" ] || fail "empty package list"
installed=$(dpkg-query -W -f='${Package} ${Status}\n' $(cat "$work/list") 2>/dev/null | awk '/install ok installed$/ { print $1 }')
while read -r p; do
  grep -qx "$p" <<<"$installed" || fail "'$p' is not an installed package"
done < "$work/list"
# "binary soname path" for every directly linked library, then their owners in one dpkg-query.
for b in "$@"; do
  libs=$(ldd "$b")
  for soname in $(readelf -d "$b" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'); do
    path=$(awk -v s="$soname" '$1 == s && $2 == "=>" { print $3 }' <<<"$libs")
    [ -n "$path" ] || fail "ldd does not resolve $soname of $b"
    echo "$(basename "$b") $soname $path"
  done
done > "$work/needed"
dpkg-query -S $(awk '{ p = $3; print p; if (p ~ /^\/usr\//) print substr(p, 5); else print "/usr" p }' "$work/needed") \
  2>/dev/null > "$work/owners"
while read -r b soname path; do
  pkg=$(awk -F': ' -v a="$path" -v b="/usr$path" -v c="${path#/usr}" '$NF == a || $NF == b || $NF == c { print $1; exit }' \
        "$work/owners" | sed -e 's/:.*//' -e 's/,.*//')
  [ -n "$pkg" ] || fail "no package owns $path"
  grep -qx "$pkg" "$work/list" || fail "$pkg ($soname, linked by $b) is missing from the list"
done < "$work/needed"
echo "runtime-packages: $(wc -l < "$work/list") packages for $(basename -a "$@" | tr '\n' ' ')"

# 2 and 3. A program linked against a library of its own.
echo 'int vrl_missing(void) { return 0; }' > "$work/lib.c"
echo 'int vrl_missing(void); int main(void) { return vrl_missing(); }' > "$work/main.c"
cc -shared -fPIC -o "$work/libvrlmissing.so" "$work/lib.c" &&
  cc -o "$work/prog" "$work/main.c" -L"$work" -lvrlmissing || fail "cannot compile the test program"
LD_LIBRARY_PATH=$work "$script" "$work/prog" > /dev/null 2> "$work/err3"; code=$?
[ "$code" -eq 1 ] && grep -q "no Debian package owns $work/libvrlmissing.so" "$work/err3" ||
  fail "a library no package owns: exit $code, $(cat "$work/err3")"
rm "$work/libvrlmissing.so"
"$script" "$work/prog" > /dev/null 2> "$work/err2"; code=$?
[ "$code" -eq 1 ] && grep -q "libvrlmissing.so => not found" "$work/err2" ||
  fail "a library ldd cannot find: exit $code, $(cat "$work/err2")"
echo "runtime_packages_test: 3 passed, 0 failed"
