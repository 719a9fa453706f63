#!/usr/bin/env bash
# The viewer starts from render's view of a cpfg object, in a real window
# under Xvfb (app/plant_view.h is shared by both):
#  1. a .l with a view file (`projection: parallel`, a viewpoint, a light
#     direction): the viewer's first frame covers the pixels render's
#     picture covers (masks compared right of the panel), in the same
#     colours (the same lights);
#  2. a 2D figure of cpfg's `5 pixels` line width is drawn 5 pixels wide
#     (it was a one-pixel line), also with the view file given by --view;
#  3. a .l without a view file: cpfg's default view, parallel from +Z, as
#     render draws it;
#  4. a 2D figure: the same lines on white, framed tightly.
# Usage: viewer_cpfg_test.sh SYLVA_BINARY SOURCE_DIR WORK_DIR
set -euo pipefail
sylva="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
display=":$((200 + $$ % 500))"
Xvfb "$display" -screen 0 1280x800x24 -nolisten tcp >"$work/xvfb.log" 2>&1 &
xvfb=$!
trap 'kill "$xvfb" 2>/dev/null; true' EXIT
export DISPLAY="$display"
for _ in $(seq 50); do [[ -e "/tmp/.X11-unix/X${display#:}" ]] && break; sleep 0.1; done

# 1. A 3D branching plant seen from the side and above, in parallel
# projection, lit from its view file's light.
cat >"$work/plant.l" <<'EOF'
axiom: F(4) [&(40) F(3) [+(50) F(2)]] [^(35) /(90) F(3)] [+(60) &(30) F(2.5)] [-(50) ^(20) F(2)]
EOF
cat >"$work/plant.v" <<'EOF'
initial line width: 0.4
viewpoint: 3,1,2
view reference point: 0,2,0
projection: parallel
light direction: 1,0.5,0.5
EOF
"$sylva" render "$work/plant.l" -o "$work/plant-render.png" --size 960x540
"$sylva" view "$work/plant.l" --screenshot "$work/plant-view.png" --frames 5 --size 960x540

# 2. cpfg's pixel widths in a 2D figure: a vertical line 5 pixels wide.
printf 'axiom: F(10)\n' >"$work/px.l"
printf 'initial line width: 5 pixels\n' >"$work/px.v"
"$sylva" render "$work/px.l" -o "$work/px-render.png" --size 960x540
"$sylva" view "$work/px.l" --screenshot "$work/px-view.png" --frames 5 --size 960x540
# --view names the view file of a grammar without NAME.v beside it.
printf 'axiom: F(10)\n' >"$work/lone.l"
"$sylva" view "$work/lone.l" --view "$work/px.v" --screenshot "$work/px-flag.png" --frames 5 \
  --size 960x540
if "$sylva" view "$src/examples/scenes/flag.xml" --view "$work/px.v" --screenshot "$work/s.png" \
  --frames 2 2>"$work/scene.err"; then
  echo "view SCENE --view should be exit 2"; exit 1
fi
grep -q "is for grammars" "$work/scene.err"

# 3. No view file: cpfg's default view (parallel, from +Z) of a 3D plant.
cp "$work/plant.l" "$work/bare.l"
"$sylva" render "$work/bare.l" -o "$work/bare-render.png" --size 960x540
"$sylva" view "$work/bare.l" --screenshot "$work/bare-view.png" --frames 5 --size 960x540

# 4. A 2D figure (ABOP's Koch island): lines on white, framed tightly.
cp "$src/grammars/abop/fig1_06_koch_island.lsys" "$work/koch.lsys"
"$sylva" render "$work/koch.lsys" -o "$work/koch-render.png" --size 960x540
"$sylva" view "$work/koch.lsys" --screenshot "$work/koch-view.png" --frames 5 --size 960x540

python3 - "$work" "$src/tests/app" <<'PY'
import sys; sys.dont_write_bytecode = True; sys.path.insert(0, sys.argv[2]); import png_rows as png
work = sys.argv[1]
PANEL = 360  # the panel covers the columns left of this one

def mask(path, bg):
    w, h, rows = png.read(path)
    return w, h, {(x, y) for y in range(h) for x in range(PANEL, w)
                  if sum(abs(rows[y][4 * x + c] - bg[c]) for c in range(3)) > 30}

def compare(name):
    w, h, rows = png.read(f'{work}/{name}-render.png')
    bg = rows[0][4 * (w - 1):4 * (w - 1) + 3]  # the top-right corner: background
    _, _, a = mask(f'{work}/{name}-render.png', bg)
    vw, vh, b = mask(f'{work}/{name}-view.png', bg)
    assert (vw, vh) == (w, h), (vw, vh)
    union, differ = len(a | b), len(a ^ b)
    print(f'{name}: render covers {len(a)} pixels right of the panel, the viewer {len(b)}; '
          f'{differ} differ ({100.0 * differ / max(union, 1):.2f} % of {union})')
    assert len(a) > 2000, f'{name}: render drew too little to compare ({len(a)} pixels)'
    assert differ <= 0.05 * union, f'{name}: the viewer does not start from render\'s view'
    # The same lights: the colours of the pixels both cover agree (the
    # viewer's smaller shadow map moves a few shadow edges).
    _, _, view = png.read(f'{work}/{name}-view.png')
    both = a & b
    mean = sum(max(abs(rows[y][4 * x + c] - view[y][4 * x + c]) for c in range(3))
               for x, y in both) / max(len(both), 1)
    print(f'{name}: mean colour difference {mean:.3f} of 255 over {len(both)} pixels')
    assert mean < 1.0, f'{name}: the viewer lights the plant otherwise than render'

compare('plant')
compare('bare')
compare('koch')
# Framed tightly: the island spans at least 90 % of the height (the margin
# is 8 %), in render's picture and the viewer's alike.
for name in ('koch-render', 'koch-view'):
    w, h, rows = png.read(f'{work}/{name}.png')
    ys = [y for y in range(h) if any(sum(rows[y][4 * x:4 * x + 3]) < 3 * 200 for x in range(PANEL, w))]
    print(f'{name}: the figure spans rows {ys[0]} to {ys[-1]} of {h}')
    assert ys[-1] - ys[0] + 1 >= 0.9 * h, f'{name}: the 2D figure is not framed tightly'

# The pixel-wide line: the middle row crosses 4 to 6 dark pixels in both.
for name in ('px-render', 'px-view', 'px-flag'):
    w, h, rows = png.read(f'{work}/{name}.png')
    row = rows[h // 2]
    dark = sum(1 for x in range(PANEL, w) if sum(row[4 * x:4 * x + 3]) < 3 * 200)
    print(f'{name}: the `5 pixels` line covers {dark} pixels of the middle row')
    assert 4 <= dark <= 6, f'{name}: a 5-pixel line drawn {dark} pixels wide'
PY
echo "the viewer starts from render's view, projection, lights and pixel widths"
