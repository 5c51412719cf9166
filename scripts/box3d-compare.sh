#!/usr/bin/env bash
# Box3D beside cps on Box3D's two pyramid scenes (large_pyramid, many_pyramids): builds Box3D
# (erincatto/box3d; measured with 0.1.0) from a source folder you give, in Release with its
# default SIMD and one thread, with a small driver of ours that builds each scene as Box3D's
# benchmark does (shared/benchmarks.c, default world, continuous on) and times steps 2 to 21 in
# thread CPU time; then times cps's scenes of the same name (`cps bench --scene`, the same window,
# the same clock) and prints both in ms a step with the ratio, and each engine's top after 200
# steps. Rounds alternate the engines; each figure is the median of the rounds. Then, per scene,
# where a step goes: Box3D's own profile (b3World_GetProfile, wall ms, mean over the same steps)
# beside cps's stage table (`cps bench`, wall ms), each from its last round.
#
# With --growth SIZES, the cost growth instead: for each size N (comma-separated, as `cps bench
# --growth pyramid --sizes`), Box3D's wall pyramid (CreateLargePyramid's layout and world) with as
# many cubes as cps's pyramid_N has boxes, timed over steps 2 to 21; cps's pyramid_N at Box3D's
# world (the soft step with large_pyramid's settings); and cps's pyramid_N at the paper's defaults
# under the wide solver (`--solver coloured-pgs --row-precision float`). It prints us a step a
# body, the median of the rounds, and each series' log-log slope against bodies. cps's times are
# `cps bench --growth`'s (6 steps from 1 s), so each engine is timed over its own window and
# layout (pyramid_N's boxes stand 2 cm apart, Box3D's touch): the slopes compare, the times a
# body only roughly.
#
# Nothing is downloaded, and CI does not run it.
# Usage: scripts/box3d-compare.sh [--growth SIZES] BOX3D_SOURCE_DIR [ROUNDS (3)] [CPS (build/demos/cps)]
set -euo pipefail
cd "$(dirname "$0")/.."
usage="usage: scripts/box3d-compare.sh [--growth SIZES] BOX3D_SOURCE_DIR [ROUNDS] [CPS]"
growth=
if [ "${1:-}" = --growth ]; then
  growth=${2:-}
  [[ "$growth" =~ ^[0-9]+(,[0-9]+)+$ ]] || { echo "box3d-compare: --growth takes at least two sizes, comma-separated (such as 100,1000,5000), not '$growth'" >&2; exit 2; }
  shift 2
fi
src=${1:?$usage}
rounds=${2:-3}
[[ "$rounds" =~ ^[1-9][0-9]?$ ]] || { echo "box3d-compare: ROUNDS must be an integer in [1, 99], not '$rounds'" >&2; exit 2; }
cps=${3:-build/demos/cps}
[ -f "$src/shared/benchmarks.c" ] || { echo "box3d-compare: $src has no shared/benchmarks.c (a Box3D source folder?)" >&2; exit 2; }
[ -x "$cps" ] || { echo "box3d-compare: no cps at $cps (build it first)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cmake -S "$src" -B "$work/build" -DCMAKE_BUILD_TYPE=Release -DBOX3D_SAMPLES=OFF \
  -DBOX3D_UNIT_TESTS=OFF -DBOX3D_BENCHMARKS=ON -DBOX3D_DOCS=OFF > "$work/cmake.log" 2>&1
cmake --build "$work/build" --parallel "$(nproc)" > "$work/build.log" 2>&1
box3d_lib=$(find "$work/build" -name 'libbox3d.a' | head -1)
shared_lib=$(find "$work/build" -name 'libshared.a' | head -1)
[ -n "$box3d_lib" ] && [ -n "$shared_lib" ] || { echo "box3d-compare: the Box3D build made no libbox3d.a / libshared.a (see $work)" >&2; exit 1; }

cat > "$work/driver.c" <<'C'
// Times steps 2..21 of a Box3D benchmark scene in thread CPU time (ms a step); with "top", steps
// 200 and prints the highest box centre plus 0.5 m; with "profile", prints the mean of Box3D's
// own profile over steps 2..21 (wall ms) as "stage ms" lines. "wall BASE" builds a wall pyramid
// of BASE cubes in its bottom row as CreateLargePyramid builds its 100 (ground, density, sleeping
// off) and prints ms a step over steps 2..21 and its cubes.
#define _GNU_SOURCE
#include "benchmarks.h"
#include "box3d/box3d.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double cpu_ms(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * (double)t.tv_sec + 1e-6 * (double)t.tv_nsec;
}

static int create_wall(b3WorldId world, int base) {
  b3World_EnableSleeping(world, false);
  b3BodyDef ground = b3DefaultBodyDef();
  ground.position = (b3Pos){0.0f, -1.0f, 0.0f};
  b3BoxHull slab = b3MakeBoxHull(400.0f, 1.0f, 400.0f);
  b3ShapeDef ground_shape = b3DefaultShapeDef();
  b3CreateHullShape(b3CreateBody(world, &ground), &ground_shape, &slab.base);
  b3BodyDef body = b3DefaultBodyDef();
  body.type = b3_dynamicBody;
  b3ShapeDef shape = b3DefaultShapeDef();
  shape.density = 100.0f;
  const float h = 0.5f;
  b3BoxHull cube = b3MakeBoxHull(h, h, h);
  int cubes = 0;
  for (int i = 0; i < base; ++i) {
    for (int j = i; j < base; ++j, ++cubes) {
      body.position = (b3Pos){(i + 1.0f) * h + 2.0f * (j - i) * h - h * base, (2.0f * i + 1.0f) * h, 0.0f};
      b3CreateHullShape(b3CreateBody(world, &body), &shape, &cube.base);
    }
  }
  return cubes;
}

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  b3WorldDef def = b3DefaultWorldDef();
  def.enableContinuous = true;
  def.workerCount = 1;
  b3WorldId world = b3CreateWorld(&def);
  const float dt = 1.0f / 60.0f;
  if (strcmp(argv[1], "wall") == 0) {
    if (argc < 3) return 2;
    const int cubes = create_wall(world, atoi(argv[2]));
    b3World_Step(world, dt, 4);
    const double start = cpu_ms();
    for (int k = 0; k < 20; ++k) b3World_Step(world, dt, 4);
    printf("%.4f %d\n", (cpu_ms() - start) / 20.0, cubes);
    b3DestroyWorld(world);
    return 0;
  }
  void (*create)(b3WorldId) = strcmp(argv[1], "large_pyramid") == 0 ? CreateLargePyramid : CreateManyPyramids;
  create(world);
  b3World_Step(world, dt, 4);
  const double start = cpu_ms();
  b3Profile sum = {0};
  for (int k = 0; k < 20; ++k) {
    b3World_Step(world, dt, 4);
    const b3Profile p = b3World_GetProfile(world);
    sum.step += p.step;
    sum.pairs += p.pairs;
    sum.collide += p.collide;
    sum.prepareConstraints += p.prepareConstraints;
    sum.integrateVelocities += p.integrateVelocities;
    sum.warmStart += p.warmStart;
    sum.solveImpulses += p.solveImpulses;
    sum.integratePositions += p.integratePositions;
    sum.relaxImpulses += p.relaxImpulses;
    sum.applyRestitution += p.applyRestitution;
    sum.storeImpulses += p.storeImpulses;
  }
  printf("%.3f\n", (cpu_ms() - start) / 20.0);
  if (argc > 2 && strcmp(argv[2], "profile") == 0) {
    printf("pairs %.3f\ncollide %.3f\nprepare %.3f\nintegrate_velocities %.3f\nwarm_start %.3f\n"
           "solve %.3f\nintegrate_positions %.3f\nrelax %.3f\nrestitution %.3f\nstore %.3f\nstep %.3f\n",
           sum.pairs / 20, sum.collide / 20, sum.prepareConstraints / 20, sum.integrateVelocities / 20,
           sum.warmStart / 20, sum.solveImpulses / 20, sum.integratePositions / 20,
           sum.relaxImpulses / 20, sum.applyRestitution / 20, sum.storeImpulses / 20, sum.step / 20);
  }
  if (argc > 2 && strcmp(argv[2], "top") == 0) {
    for (int k = 21; k < 200; ++k) b3World_Step(world, dt, 4);
    b3Counters c = b3World_GetCounters(world);
    float top = -1e30f;
    for (int i = 1; i <= c.bodyCount; ++i) {
      b3BodyId id = {i, (uint16_t)(world.index1 - 1), 1};
      if (!b3Body_IsValid(id) || b3Body_GetType(id) != b3_dynamicBody) continue;
      const float y = (float)b3Body_GetTransform(id).p.y + 0.5f;
      if (y > top) top = y;
    }
    printf("%.4f\n", top);
  }
  b3DestroyWorld(world);
  return 0;
}
C
cc -O3 -DNDEBUG -std=gnu17 -I "$src/include" -I "$src/shared" "$work/driver.c" -o "$work/driver" \
  "$shared_lib" "$box3d_lib" -lm -lpthread

median() { sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }

if [ -n "$growth" ]; then
  # Box3D's world as cps's large_pyramid sets it (demos/scenes/box3d_pyramids.cpp).
  box3d_world=(--push soft --soft-substeps 4 --iterations 1 --warm-start 1 --friction 0.6
    --friction-model coupled --restitution 0 --contact-margin 0.02 --manifold-points 4
    --contact-recycle-distance 0.05 --contact-hertz 30 --contact-damping-ratio 10
    --contact-push-max-speed 3 --dt 0.016666666666666666)
  for ((r = 0; r < rounds; ++r)); do
    "$cps" bench --growth pyramid --sizes "$growth" --solver coloured-pgs --row-precision float --json \
      2> "$work/cps.err" > "$work/cps-paper-$r.json" || { status=$?; cat "$work/cps.err" >&2; exit "$status"; }
    "$cps" bench --growth pyramid --sizes "$growth" "${box3d_world[@]}" --json \
      2> "$work/cps.err" > "$work/cps-soft-$r.json" || { status=$?; cat "$work/cps.err" >&2; exit "$status"; }
    # Box3D's wall with as many cubes as pyramid_N has boxes (its bodies but the ground).
    python3 -c 'import json, sys
for p in json.load(sys.stdin)["growth_series"]["points"]:
    cubes = int(p["bodies"]) - 1
    base = int(((8 * cubes + 1) ** 0.5 - 1) / 2)
    assert base * (base + 1) // 2 == cubes, "pyramid_N is not a wall of b (b + 1) / 2 boxes: %d" % cubes
    print(base)' < "$work/cps-paper-$r.json" > "$work/bases.txt"
    while read -r base; do "$work/driver" wall "$base"; done < "$work/bases.txt" > "$work/box3d-$r.txt"
  done
  python3 - "$work" "$rounds" <<'PY'
import json, math, statistics, sys
work, rounds = sys.argv[1], int(sys.argv[2])
def slope(xs, ys):  # least squares of log y on log x
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)
def cps_series(name):  # (bodies, median us a step a body) per size
    runs = [json.load(open("%s/cps-%s-%d.json" % (work, name, r)))["growth_series"]["points"] for r in range(rounds)]
    return [int(p["bodies"]) for p in runs[0]], [statistics.median(run[i]["us_per_body"] for run in runs) for i in range(len(runs[0]))]
bodies, paper = cps_series("paper")
_, soft = cps_series("soft")
box3d_runs = [[line.split() for line in open("%s/box3d-%d.txt" % (work, r)).read().splitlines()] for r in range(rounds)]
cubes = [int(c) for _, c in box3d_runs[0]]
box3d = [statistics.median(1000 * float(run[i][0]) / cubes[i] for run in box3d_runs) for i in range(len(cubes))]
step = lambda per_body, n: [p * m for p, m in zip(per_body, n)]
print("us a step a body (Box3D's cubes; cps's bodies, the ground among them), medians of %d rounds:" % rounds)
print()
print("| cubes | Box3D | cps at Box3D's world | cps / Box3D | cps at the paper's defaults (coloured-pgs, float rows) |")
print("|---|---|---|---|---|")
for i, n in enumerate(cubes):
    print("| %d | %.2f | %.2f | %.2f | %.2f |" % (n, box3d[i], soft[i], soft[i] / box3d[i], paper[i]))
print("| slope against bodies | %.3f | %.3f | | %.3f |" % (
    slope(cubes, step(box3d, cubes)), slope(bodies, step(soft, bodies)), slope(bodies, step(paper, bodies))))
PY
  exit 0
fi
printf '| scene | Box3D ms/step | cps ms/step | cps / Box3D | Box3D top after 200 steps (m) | cps top (m) |\n|---|---|---|---|---|---|\n'
for scene in large_pyramid many_pyramids; do
  : > "$work/box3d.txt"
  : > "$work/cps.txt"
  for ((r = 0; r < rounds; ++r)); do
    "$work/driver" "$scene" profile > "$work/box3d-$scene.profile"
    head -1 "$work/box3d-$scene.profile" >> "$work/box3d.txt"
    "$cps" bench --scene "$scene" --json 2> /dev/null > "$work/cps-$scene.json"
    python3 -c 'import json, sys; print(json.load(sys.stdin)["physics"][0]["matrix_free_us_per_step"] / 1000)' \
      < "$work/cps-$scene.json" >> "$work/cps.txt"
  done
  box3d_ms=$(median < "$work/box3d.txt")
  cps_ms=$(median < "$work/cps.txt")
  box3d_top=$("$work/driver" "$scene" top | tail -1)
  cps_top=$("$cps" simulate "$scene" --json 2> /dev/null | python3 -c 'import json, sys; print("%.4f" % json.load(sys.stdin)["metrics"]["top_m"])')
  printf '| %s | %.2f | %.2f | %.2f | %s | %s |\n' "$scene" "$box3d_ms" "$cps_ms" \
    "$(awk -v a="$cps_ms" -v b="$box3d_ms" 'BEGIN {print a / b}')" "$box3d_top" "$cps_top"
done

# Where a step goes, from each engine's last round (wall ms a step; the stages are each engine's
# own, so a row pairs only what the two do alike).
for scene in large_pyramid many_pyramids; do
  echo
  echo "Where a step of $scene goes (wall ms; Box3D's b3Profile, cps's stage table):"
  python3 - "$work/box3d-$scene.profile" "$work/cps-$scene.json" <<'PY'
import json, sys
b3 = dict(line.split() for line in open(sys.argv[1]).read().splitlines()[1:])
b3 = {k: float(v) for k, v in b3.items()}
cps = {k: v / 1000 for k, v in json.load(open(sys.argv[2]))["physics"][0]["matrix_free_stages_us_per_step"].items()}
rows = [
    ("broad and narrow phase", b3["pairs"] + b3["collide"], "collide", cps["collide"]),
    ("the warm-start match (and the paper's rows where a method reads them)", None, "rows", cps["rows"]),
    ("prepare", b3["prepare"], "prepare", cps["prepare"]),
    ("warm start and biased sweeps", b3["warm_start"] + b3["solve"], "solve", cps["solve"]),
    ("relax", b3["relax"], "relax", cps["relax"]),
    ("integrate", b3["integrate_velocities"] + b3["integrate_positions"], "integrate", cps["integrate"]),
    ("restitution and store", b3["restitution"] + b3["store"], "store", cps["store"] + cps["other"]),
]
print("| work | Box3D ms | cps stage | cps ms |\n|---|---|---|---|")
for work, b, stage, c in rows:
    print("| %s | %s | %s | %.2f |" % (work, "-" if b is None else "%.2f" % b, stage, c))
print("| whole step | %.2f | | %.2f |" % (b3["step"], sum(cps.values())))
PY
done
