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
# Nothing is downloaded, and CI does not run it.
# Usage: scripts/box3d-compare.sh BOX3D_SOURCE_DIR [ROUNDS (3)] [CPS (build/demos/cps)]
set -euo pipefail
cd "$(dirname "$0")/.."
src=${1:?usage: scripts/box3d-compare.sh BOX3D_SOURCE_DIR [ROUNDS] [CPS]}
rounds=${2:-3}
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
// own profile over steps 2..21 (wall ms) as "stage ms" lines.
#define _GNU_SOURCE
#include "benchmarks.h"
#include "box3d/box3d.h"
#include <stdio.h>
#include <string.h>
#include <time.h>

static double cpu_ms(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * (double)t.tv_sec + 1e-6 * (double)t.tv_nsec;
}

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  void (*create)(b3WorldId) = strcmp(argv[1], "large_pyramid") == 0 ? CreateLargePyramid : CreateManyPyramids;
  b3WorldDef def = b3DefaultWorldDef();
  def.enableContinuous = true;
  def.workerCount = 1;
  b3WorldId world = b3CreateWorld(&def);
  create(world);
  const float dt = 1.0f / 60.0f;
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
