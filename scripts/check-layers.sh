#!/usr/bin/env bash
# Fails (exit 1) naming FILE:LINE and the include when an #include in libvox runs against the stages' order
# (docs/architecture.md): a stage includes only its own headers and the public headers (vox/STAGE/...) of the stages
# below it; a private header (libvox/src/STAGE/x.h, included as "STAGE/x.h") only from its own stage's sources.
# Usage: scripts/check-layers.sh [ROOT]   ROOT holds libvox/ (default: this checkout; tests pass a planted copy).
set -euo pipefail
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
root=${root%/}

# The order, stage: the stages below it that it may include. Kept acyclic by construction: a stage lists only
# stages written above it here. Change it together with the picture in docs/architecture.md.
order='
core:
io: core
import: core io
voxelize: core
trace: core
export: core io
sets: core io voxelize
distance: core voxelize
volume: core voxelize
'

files=()
for dir in libvox/src libvox/include/vox libvox/oiio; do
  [ -d "$root/$dir" ] || continue
  while IFS= read -r -d '' f; do files+=("$f"); done < <(find "$root/$dir" -type f \( -name '*.h' -o -name '*.cpp' \) -print0 | sort -z)
done
if [ ${#files[@]} -eq 0 ]; then
  echo "check-layers.sh: no sources under $root/libvox" >&2
  exit 1
fi

# awk sees each file as ROOT/...; names are printed relative to ROOT.
awk -v root="$root/" -v order="$order" '
function fail(msg) { printf "%s:%d: %s\n", rel, FNR, msg; bad++ }
BEGIN {
  n = split(order, lines, "\n")
  for (i = 1; i <= n; i++) {
    if (lines[i] !~ /:/) continue
    split(lines[i], kv, ":")
    stage = kv[1]; gsub(/[ \t]/, "", stage)
    known[stage] = 1
    m = split(kv[2], below, " ")
    for (j = 1; j <= m; j++) {
      if (!(below[j] in known)) { printf "check-layers.sh: stage %s lists %s, which is not above it in the order\n", stage, below[j]; exit 2 }
      may[stage, below[j]] = 1
    }
  }
}
FNR == 1 {
  rel = substr(FILENAME, length(root) + 1)
  home = ""; private = 0
  if (rel ~ /^libvox\/src\//) { home = substr(rel, 12); private = 1 }
  else if (rel ~ /^libvox\/include\/vox\//) home = substr(rel, 20)
  else if (rel ~ /^libvox\/oiio\//) { home = "io/"; private = 1 }  # the OpenImageIO module is io'"'"'s bridge
  if (index(home, "/") == 0) { fail("not inside a stage folder (libvox/src/STAGE/, libvox/include/vox/STAGE/)"); home = "?" }
  else {
    home = substr(home, 1, index(home, "/") - 1)
    if (!(home in known)) { fail("stage " home " is not in the order of scripts/check-layers.sh and docs/architecture.md"); home = "?" }
  }
}
/^[ \t]*#[ \t]*include[ \t]*["<]/ {
  if (home == "?") next
  line = $0
  sub(/^[ \t]*#[ \t]*include[ \t]*/, "", line)
  quoted = substr(line, 1, 1) == "\""
  path = substr(line, 2)
  sub(/[">].*$/, "", path)
  text = "#include " substr(line, 1, length(path) + 2)
  if (index(path, "/") == 0) next  # system and third-party headers (and same-folder names, which none use)
  first = substr(path, 1, index(path, "/") - 1)
  if (first == "vox") {
    rest = substr(path, 5)
    if (index(rest, "/") == 0) { fail(text ": a vox/ header outside any stage"); next }
    target = substr(rest, 1, index(rest, "/") - 1)
    if (!(target in known)) { fail(text ": stage " target " is not in the order"); next }
    if (target != home && !((home, target) in may))
      fail(text ": " home " may not include " target " (" home " is not above it in docs/architecture.md)")
    next
  }
  if (!quoted || !(first in known)) next
  if (!private) fail(text ": a public header includes a private one (libvox/src/" path ")")
  else if (first != home) fail(text ": " home " reaches into the internals of " first " (include its vox/" first "/ header)")
}
END {
  if (bad) { printf "check-layers.sh: %d include(s) against the stages'"'"' order (docs/architecture.md)\n", bad; exit 1 }
}
' "${files[@]}"
