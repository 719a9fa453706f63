#!/usr/bin/env bash
# Renders the README's pictures into docs/images/ with `sylva render`
# (headless, EGL on whatever OpenGL the machine has; llvmpipe here).
set -euo pipefail
cd "$(dirname "$0")/.."
sylva=build/src/app/sylva
out=docs/images
mkdir -p "$out"
render() { "$sylva" render "grammars/$1.lsys" --size 480x360 -o "$out/$2.png" "${@:3}"; }
render abop/fig1_06_koch_island koch_island
render abop/fig1_10a_dragon_curve dragon_curve -n 12
render abop/fig1_24f_bracketed_plant bracketed_plant_f
render abop/fig1_31a_hogeweg_hesper hogeweg_hesper_a
"$sylva" render grammars/abop/fig2_06a_monopodial.lsys --size 720x480 -o "$out/monopodial_a.png"
render abop/fig2_07b_sympodial sympodial_b
render abop/fig2_08b_ternary ternary_b
render abop/fig1_25_bush bush --camera 30,25,0
render plants/leafy_stem leafy_stem --camera 20,20,0
build/examples/particles_bouncing_box 2000 3 "$out/particles_bouncing_box.png"
build/examples/particles_fireworks 2.6 "$out/particles_fireworks.png"
build/examples/particles_flag 3 "$out/particles_flag.png"
build/examples/particles_flock 3000 8 "$out/particles_flock.png"
build/examples/particles_snow 200000 4 "$out/particles_snow.png"
