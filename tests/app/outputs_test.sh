#!/usr/bin/env bash
# What `sylva` does with its outputs, through the real process:
#  1. output it cannot write (stdout on a full device) is exit 1, not 0;
#  2. render writes JPEG for .jpg and refuses an unknown extension up front;
#  3. SIGTERM while an output is being written leaves no temporary file;
#  4. a 300-character file name is a message and exit 1 (not an abort);
#  5. -o onto a symbolic link writes the file it points to; the link stays.
# Usage: outputs_test.sh SYLVA_BINARY SOURCE_DIR WORK_DIR [graphics|nographics]
set -euo pipefail
sylva="$1"; src="$2"; work="$3"; graphics="${4:-graphics}"
rm -rf "$work"; mkdir -p "$work"
g="$src/grammars/abop/fig1_24a_bracketed_plant.lsys"
fail() { echo "FAIL: $*"; exit 1; }

# 1.
set +e
"$sylva" derive "$g" --stats > /dev/full 2>"$work/full.err"; code=$?
set -e
[[ $code == 1 ]] || fail "--stats > /dev/full exited $code"
grep -q "cannot write to standard output" "$work/full.err" || fail "no message: $(cat "$work/full.err")"
echo "ok: --stats > /dev/full is exit 1"

# 2.
if [[ $graphics == graphics ]]; then
"$sylva" render "$g" -n 2 --size 64x48 -o "$work/plant.jpg" 2>/dev/null
[[ $(head -c 2 "$work/plant.jpg" | od -An -tx1 | tr -d ' ') == ffd8 ]] || fail "plant.jpg is not a JPEG"
set +e
"$sylva" render "$g" -o "$work/plant.bmp" 2>"$work/bmp.err"; code=$?
set -e
[[ $code == 2 ]] || fail "render -o .bmp exited $code"
[[ ! -e "$work/plant.bmp" ]] || fail "plant.bmp was written"
grep -q "unknown image format" "$work/bmp.err" || fail "no message: $(cat "$work/bmp.err")"
echo "ok: .jpg is JPEG, .bmp is refused"
else
  set +e
  "$sylva" render "$g" -o "$work/plant.png" 2>"$work/nographics.err"; code=$?
  set -e
  [[ $code == 2 ]] || fail "render without the renderer exited $code"
  grep -q "not installed\|built without" "$work/nographics.err" || fail "no message: $(cat "$work/nographics.err")"
  echo "ok: render in a build without the renderer is exit 2 with a message"
fi

# 3. A mesh large enough to take a while to write; the signal arrives while
# its temporary file exists.
"$sylva" mesh "$src/grammars/abop/fig2_06a_monopodial.lsys" -n 17 --sides 8 -o "$work/big.obj" 2>/dev/null &
pid=$!
seen=0
for _ in $(seq 2000); do
  if compgen -G "$work/big.obj.tmp-*" >/dev/null || compgen -G "$work/big.mtl.tmp-*" >/dev/null; then seen=1; break; fi
  kill -0 $pid 2>/dev/null || break
  sleep 0.01
done
if [[ $seen == 1 ]]; then
  kill -TERM $pid
  set +e; wait $pid; code=$?; set -e
  [[ $code == 143 ]] || fail "killed mesh exited $code, expected 143 (SIGTERM)"
  leftovers=$(ls "$work" | grep -c "tmp-" || true)
  [[ $leftovers == 0 ]] || fail "temporary files left after SIGTERM: $(ls "$work")"
  echo "ok: SIGTERM while writing leaves no temporary file"
else
  wait $pid || true
  echo "note: the mesh was written before a temporary file was seen; signal check skipped"
fi

# 4.
long="$work/$(printf 'x%.0s' $(seq 300)).txt"
set +e
"$sylva" derive "$g" -o "$long" 2>"$work/long.err"; code=$?
set -e
[[ $code == 1 ]] || fail "a 300-character name exited $code"
grep -q "File name too long" "$work/long.err" || fail "no message: $(cat "$work/long.err")"
echo "ok: a 300-character name is exit 1 with a message"

# 5.
mkdir -p "$work/real"; echo old > "$work/real/word.txt"
ln -s real/word.txt "$work/link.txt"
"$sylva" derive "$g" -n 1 -o "$work/link.txt"
[[ -L "$work/link.txt" ]] || fail "the link was replaced"
[[ $(cat "$work/real/word.txt") == "F[+F]F[-F]F" ]] || fail "the link's file holds $(cat "$work/real/word.txt")"
echo "ok: -o onto a link writes its file and keeps the link"
