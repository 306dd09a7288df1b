#!/bin/sh
# Writes the man pages of the CLI from its own help text (help2man): atmos.1 and one
# atmos-COMMAND.1 per command that `atmos --help` lists, into OUTDIR.
#   make-man.sh ATMOS_BINARY OUTDIR VERSION
set -eu
atmos=$1 out=$2 version=$3
mkdir -p "$out"
command -v help2man >/dev/null 2>&1 || { echo "atmos: help2man not found; no man pages (scripts/install-deps.sh installs it)" >&2; exit 0; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
help2man --no-info --no-discard-stderr --version-string="atmos $version" \
    -n "physically based rendering of atmospheric phenomena" -o "$tmp/atmos.1" "$atmos"
# The commands: the indented lines of the "Commands:" block up to its blank line,
# "  NAME  description" (any run of spaces between the two).
"$atmos" --help | awk '/^Commands:/ {c = 1; next} c && /^$/ {exit} c && /^  [a-z]+ +[^ ]/ {print}' > "$tmp/commands"
[ -s "$tmp/commands" ] || { echo "atmos: no commands found in 'atmos --help'" >&2; exit 1; }
while read -r name desc; do
    help2man --no-info --no-discard-stderr --version-string="atmos-$name $version" \
        -n "$desc" -o "$tmp/atmos-$name.1" "$atmos $name"
done < "$tmp/commands"
mv "$tmp"/*.1 "$out"/
