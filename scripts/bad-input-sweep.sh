#!/usr/bin/env bash
# Bad-input sweep of the cps command line: every option of every command, fed bad values.
#
# Usage: scripts/bad-input-sweep.sh [CPS]          (CPS: default build/demos/cps)
#
# The options are read from `cps --help` and `cps SUB --help`, so a new option is swept without
# editing this file; the table below says which bad values each kind of option gets (the type and
# range matter: -1 is bad for --fps, not for --orbit). An option (or command) the table does not
# classify stops the sweep with exit 3 before anything runs, so coverage cannot shrink silently.
# Options whose --help shows a choice list {a, b} are classified as choices automatically.
# The world parameters' options, registered for every stepping command by one function, get
# their full lists on simulate and, on the other commands, the few values that show each
# command checks them (empty, not a number, trailing text, a leading +, past each end of the
# range).
#
# Each command line (nproc of them at a time, or SWEEP_JOBS; SWEEP_TIMEOUT, SWEEP_VERBOSE=1 to
# list every verdict) runs in a temporary folder (its cwd, with a few fixture files, made again
# after any line changed them:
# `file`, `file.png` and `file.hdf5` regular files, `adir`, `adir.json` and `dir.png` folders,
# `fifo.png` (a FIFO), `loop.png` (a link to itself) and `bomb.png` (a size bomb), scene files
# `bad.json` (a box without half_extents_m) and `notjson.json`, valid ones `a/x.json` and
# `b/x.json` of one stem, and `prior/`, a/x.json's render and figure made in another folder)
# under `timeout 20` and a
# 1 GiB address-space cap (ulimit -v; see choose_cap below), stdout and stderr captured.
# A bad command line PASSES when cps exits 2 with a message on stderr that names the option or
# the value, and wrote nothing (no new file in the cwd or in its TMPDIR, fixture files
# unchanged). Anything else FAILS: exit 0, another exit code, a timeout, a signal, bad_alloc,
# or files written. Controls (valid command lines, some at the edges of the ranges) must exit
# 0, and a self-test checks that the classifier calls an accepted line and an exit 1 failures.
#
# Prints each failure with its command line, then
#   N command lines: P refused cleanly, F failures
# and exits 1 when F > 0 (or a control or self-test failed), 3 on an unclassified option.
# Needs only bash (5.1 or later: -nt to the nanosecond), coreutils (timeout, sleep, ...) and
# findutils.
set -u
shopt -s extglob

CPS=${1:-build/demos/cps}
case $CPS in /*) ;; */*) CPS=$PWD/$CPS ;; *) CPS=$(command -v "$CPS" || echo "$CPS") ;; esac
if [[ ! -x $CPS ]]; then
  echo "bad-input-sweep: $CPS is not an executable (build it: cmake --build build --target cps)" >&2
  exit 2
fi
TIMEOUT=${SWEEP_TIMEOUT:-20}  # s per command line
MEM=$((1 << 30))              # bytes
VERBOSE=${SWEEP_VERBOSE:-0}   # 1: print every command line and its verdict
JOBS=${SWEEP_JOBS:-$(nproc)}  # command lines run at a time

root=$(mktemp -d "${TMPDIR:-/tmp}/cps-bad-input-sweep.XXXXXX")
trap 'rm -rf "$root"' EXIT
start_s=$SECONDS

# ---------------------------------------------------------------------------------------------
# The table.

# Kind of each option, by "SUB:--name" (or "*:--name" for every command that has it), and of
# each positional, by "SUB:name". The kinds' bad values are in bad_values below.
declare -A KIND=(
  ['*:--help']=skip ['top:--version']=skip
  ['*:--json']=flag ['*:--force']=flag ['*:--quick']=flag ['*:--list-runs']=flag
  ['*:--quiet']=flag ['*:--warnings-as-errors']=flag
  ['*:--rendering']=flag ['*:--contacts']=flag ['*:--velocities']=flag ['*:--forces']=flag ['*:--rods']=flag ['*:--label']=flag
  ['*:--overlay']=flag ['*:--compare']=compare
  ['*:--seconds']=seconds ['*:--fps']=fps ['*:--orbit']=orbit ['*:--speed']=speed
  ['*:--eye']=point ['*:--target']=point ['*:--fov']=fov
  ['*:--size']=size ['*:--times']=times
  ['render:--out']=out_folder ['report:--out']=out_folder ['figure:--out']=out_png ['figure:--format']=choice
  ['*:--trace']=trace ['*:--energy']=trace ['simulate:--energy-every']='param:integer:1:10000000:0:steps'
  ['simulate:--solver-error']=trace ['simulate:--at']=steps ['simulate:--sweeps']=sweeps
  ['*:--expect-hash']=hash ['*:--run']=run_id ['*:--merge']=merge
  ['simulate:scene']=scene_one ['render:scene']=scene_many ['figure:scene']=scene_figure
  ['report:scene']=scene_report ['bench:--scene']=scene_bench
  ['bench:--growth']=family ['bench:--sizes']=sizes
  ['scene:scene']=scene_one ['scene:--out']=out_json ['*:--seed']=seed
  ['export:scene']=scene_one ['export:--out']=out_glb ['*:--max-work']=max_work
  ['export:--fclib']=out_hdf5 ['export:--at']=steps
  ['report:--repeats']=repeats ['report:--jobs']='param:integer:1:256:0:threads'
  ['report:--shard']=shard
  # The sweep puts a positional's bad value in the first place, so reference's values cover frames.
  ['diff:reference']=png_in ['diff:frames']=skip ['diff:--out']=out_folder
  ['diff:--threshold']='param:real:0:255:0:levels' ['diff:--tolerance']='param:real:0:100:0:%'
)

# The world parameters' kinds come from the parameter table itself (`cps parameters --format
# tsv`: flag, type, min, max, min excluded, unit), as param:TYPE:MIN:MAX:EXCL:UNIT; their bad
# values are made from the range in bad_values below. Choices and flags are classified from --help.
# Every stepping command registers these options through one function and one set of checks
# (add_world_options), so their full lists of bad values run on one command (WORLD_FULL); every
# other command that has them gets the values that show it routes them through those checks
# (bad_values' "routed" kind): empty, not a number, trailing text, a leading +, and past each end
# of the range.
WORLD_FULL=simulate
declare -A WORLD=()
while IFS=$'\t' read -r flag type min max excl unit; do
  case $type in real | integer) KIND["*:$flag"]="param:$type:$min:$max:$excl:$unit" WORLD[$flag]=1 ;; esac
done < <("$CPS" parameters --format tsv)
if [[ -z ${KIND['*:--dt']:-} ]]; then
  echo "bad-input-sweep: '$CPS parameters --format tsv' gave no --dt row" >&2
  exit 3
fi

# The commands, each with the valid command line an option under test is added to (a short,
# cheap run: a bad value accepted by mistake costs little). The option under test is removed
# from it first; a positional under test replaces its first word after the command. Contexts
# for one option ("SUB:--name") override the command's, several separated by ';'.
declare -A BASE=(
  [list]='list'
  [simulate]='simulate stack --seconds 0.1'
  [render]='render stack --seconds 0.1 --fps 10 --size 16x16 --out out'
  [figure]='figure stack --times 0,0.1 --size 16x16 --out out/f.png'
  [report]='report intersecting_stack --list-runs --out out'
  [bench]='bench --quick --scene intersecting_stack'
  [scene]='scene stack --out out/s.json'
  [export]='export stack --seconds 0.1 --fps 10 --out out/s.glb'
  [parameters]='parameters --format tsv'
  [diff]='diff prior/x/frame_000000.png prior/x/frame_000000.png --out out'
)
RUN_ID=intersecting_stack.pgs.baumgarte.fixed.it1.ss1  # 0.1 s
MERGE_SRC=$root/merge-src                              # a complete sweep, made below
PRIOR=$root/prior                    # a/x.json (a valid scene file) and its render into out/x
DROP='{"seconds": 0.2, "bodies": [{"shape": "plane", "normal": [0, 1, 0], "offset_m": 0}, {"shape": "box", "half_extents_m": [0.5, 0.5, 0.5], "mass_kg": 1, "position_m": [0, 0.6, 0]}]}'
MERGE_DUP=$root/merge-dup  # a copy of its CSV: every run twice with MERGE_SRC, made below
MERGE_NAN=$root/merge-nan  # its first run with us_per_step nan, made below
BASE['report:--out']="report --run $RUN_ID;report --merge $MERGE_SRC;report intersecting_stack --quick;report push --quick"
BASE['report:--run']='report --out out'
BASE['bench:--growth']='bench --quick --sizes 1,2'
BASE['bench:--sizes']='bench --quick --growth stack'
BASE['simulate:--at']='simulate stack --seconds 0.1 --solver-error e.csv'
BASE['simulate:--sweeps']='simulate stack --seconds 0.1 --solver-error e.csv'
BASE['report:--merge']='report --out out'
BASE['report:--shard']='report intersecting_stack --quick --out out'
# --fclib excludes --out and --fps; intersecting_stack has contacts from its first step.
BASE['export:--fclib']='export intersecting_stack --seconds 0.1'
BASE['export:--at']='export intersecting_stack --seconds 0.1 --fclib out/s.hdf5'

NL=$'\n'
# Bad values shared by every number (one per line; an empty line is the empty value). Each is
# outside every numeric range below or not a decimal number as parse_decimal reads it.
NUM_COMMON="$NL""nan${NL}NaN${NL}-nan${NL}inf${NL}-inf${NL}infinity${NL}1e308${NL}1e12${NL}4294967297"
NUM_COMMON+="${NL}0x10${NL}1x${NL}10s${NL}+1${NL} 1${NL}1 ${NL}1,5${NL}1e${NL}.${NL}-${NL}1..2"
# Kinds whose values are not numbers get their own full lists.
bad_values() {  # KIND [CHOICES...] -> one bad value per line
  local kind=$1
  shift
  case $kind in
    seconds)  # (0, 1e5] s, a fraction allowed, at least one step of the scene's dt
      printf '%s\n' "$NUM_COMMON" -1 0 -0 1e-400 1e-300 100001 1/0 0/1 -1/60 1//60 1/ nan/1 ;;
    fps) printf '%s\n' "$NUM_COMMON" -1 0 1e-400 1e-300 9e-6 1001 1/2 ;;  # [1e-5, 1000]
    orbit) printf '%s\n' "$NUM_COMMON" -36001 36001 -1e5 1/2 ;;        # [-36000, 36000]
    max_work)  # [1, 1e18] body-iterations: NUM_COMMON but its 1e12 and 4294967297, which are allowed
      printf '%s\n' "$NUM_COMMON" | grep -vx -e 1e12 -e 4294967297
      printf '%s\n' 0 -1 0.5 1e-400 1e19 1e400 1/2 ;;
    repeats)  # timed repeats of a report run: a whole number in [3, 100]
      printf '%s\n' "$NUM_COMMON" -1 0 -0 1 2 101 1000 1.5 3.0 1e1 1/2 0x3 ;;
    speed) printf '%s\n' "$NUM_COMMON" -1 0 -0 1e-400 100.5 101 1/2 ;;  # (0, 100] s/s
    fov) printf '%s\n' "$NUM_COMMON" -1 0 1 170 180 1e-400 1/2 ;;       # (1, 170) deg
    point)  # X,Y,Z in m, each finite with |value| <= 1e6
      printf '%s\n' "" 1 1,2 1,2,3,4 , ,, 1,,3 1,2, ,1,2 a,b,c nan,0,0 0,inf,0 0,0,-inf \
        1e7,0,0 0,-1000001,0 0x10,0,0 1/2,0,0 "1;2;3" 1e400,0,0 ;;
    param:*)  # a world parameter: param:TYPE:MIN:MAX:EXCL:UNIT from the parameter table
      local type lo hi excl unit
      IFS=: read -r _ type lo hi excl unit <<< "$kind"
      # NUM_COMMON's 1e12 and 4294967297 are in range for a parameter whose max reaches them
      # (the avbd penalties): left out there.
      printf '%s\n' "$NUM_COMMON" -1 | awk -v hi="$hi" '
        !(($0 == "1e12" || $0 == "4294967297") && (hi == "inf" || $0 + 0 <= hi + 0))'
      range_ends "$lo" "$hi" "$excl"
      case $type in
        integer) printf '%s\n' 1.5 "$lo.0" 1e3 1/2 1e-320 5e-324 2147483648 99999999999999999999 ;;
        real)
          if [[ $unit == s ]]; then  # a time: a fraction is allowed, a bad one is refused
            printf '%s\n' 1e-320 5e-324 1/0 0/1 1/-60 -1/60 1/60x 1//60 /60 1/ 1/inf nan/1 1/1e-7
          else
            printf '%s\n' 1/2
          fi ;;
      esac ;;
    routed:*)  # a world parameter on a command other than WORLD_FULL: routed:TYPE:MIN:MAX:EXCL:UNIT
      local type lo hi excl unit
      IFS=: read -r _ type lo hi excl unit <<< "$kind"
      # +1 is in every range and refused only by cps's own number parser.
      printf '%s\n' "" nan 1x +1
      range_ends "$lo" "$hi" "$excl"
      case $type in
        integer) printf '%s\n' 1.5 "$((lo - 1))" ;;  # (range_ends' values are not whole numbers)
        real) if [[ $unit == s ]]; then printf '%s\n' 1/0; fi ;;
      esac ;;
    choice)  # the choices from --help
      printf '%s\n' "" nosuch "${1^^}" "$1 " " $1" "$1,$1" 1 ;;
    size)  # WxH, each in [16, 8192]
      printf '%s\n' "" 12x 8x8 15x16 16x15 8193x16 16x8193 0x0 -16x16 16x-16 1280x720x3 1280X720 \
        1280*720 0x10 99999x99999 123456x720 1e3x720 " 1280x720" nan x 1280 16x16junk ;;
    times)  # comma separated, finite, >= 0, increasing, at most 1e5 s, at most 64 of them
      printf '%s\n' "" , 0, ,0 0,,1 nan inf -inf -1 0,-1 1,0 0,0 0x10 1x 10s 1/0 1//60 -1/60 1e308 1e12 \
        100001 4294967297 0,1e-400x "0;1" "$(seq_csv 65)" ;;
    compare)  # PARAM=V1,...,Vn (2 to 8 distinct values the table accepts) or a choice alone
      printf '%s\n' "" nosuch nosuch=1,2 gravity=0,0,-10 collision=true,false PUSH "push " " push" \
        beta beta= =0.1,0.2 beta=2,3 beta=0.1,2 beta=nan,0.1 beta=0.1,inf beta=0x10,0.1 \
        beta=0.1 push=split beta=0.1,0.2,0.3,0.4,0.5,0.6,0.7,0.8,0.9 beta=0.1,0.1 beta=0.5,0.50 \
        push=split,split push=sideways,split "beta=0.1,,0.2" beta=0.1,0.2, "beta=0.1, 0.2" \
        beta==0.1,0.2 iterations=1,0 iterations=1,1.5 dt=0,1/60 dt=1/0,1/60 \
        "beta=0.1;0.2" iterations=1,2,3,4,5,6,7,8,9 ;;
    png_in)  # not a PNG file, or a file beside a folder (the base's other input is a PNG)
      printf '%s\n' "" nosuch.png file file.png dir.png adir bad.json fifo.png loop.png bomb.png ;;
    out_folder)  # cannot be a folder: an existing file, a path under a file, a device
      printf '%s\n' "" file file/sub /dev/null ;;
    out_png)  # not a PNG path, nor a folder, that can be written (an existing folder takes the figure)
      printf '%s\n' "" file.png file/f.png f.txt file /dev/null ;;
    steps)  # comma-separated step indices of the run: [0, 5] for the base's 6 steps
      printf '%s\n' "" , x -1 6 1,,2 1, ,1 1.5 0x1 1e3 +1 " 1" "1 " "1;2" nan 4294967297 \
        99999999999999999999 ;;
    sweeps)  # comma-separated sweep counts in [0, 1e6]
      printf '%s\n' "" , x -1 1000001 1,,2 1, 1.5 0x10 1e3 +1 " 1" "1;2" nan 4294967297 ;;
    trace)  # cannot be written as a new trace
      printf '%s\n' "" file file/t.csv adir ;;
    hash)  # 16 hex digits (0x prefix allowed)
      printf '%s\n' "" xyz 0123456789abcde 0123456789abcdef0 0123456789abcdeg 0x0123456789abcde \
        -123456789abcdef " 0123456789abcdef" "0123456789abcdef " 0x 0xx0123456789abcdef nan ;;
    run_id)  # scene.solver.push.friction.itN.ssM, then optionally .wsF (warm start F in [0, 1]);
             # or a study: SCENE.solver_error|references|energy, mass_ratio.R.SOLVER.PUSH
      local good=intersecting_stack.pgs.baumgarte.fixed
      printf '%s\n' "" garbage intersecting_stack "$good.it25" "$good.it25.ss1.extra" \
        nosuch.pgs.baumgarte.fixed.it1.ss1 intersecting_stack.sor.baumgarte.fixed.it1.ss1 \
        intersecting_stack.pgs.nopush.fixed.it1.ss1 intersecting_stack.pgs.baumgarte.nofric.it1.ss1 \
        "$good.it0.ss1" "$good.it-1.ss1" "$good.it10001.ss1" "$good.it4294967297.ss1" \
        "$good.it1x.ss1" "$good.it0x10.ss1" "$good.it1e3.ss1" "$good.it.ss1" "$good.it 1.ss1" \
        "$good.x1.ss1" "$good.it1.ss0" "$good.ss1.it1" "$good.it1.ss1001" "$good.it1.ss-1" \
        "$good.it1.ss1.5" ..... "$good.IT1.SS1" \
        "$good.it1.ss1.ws2" "$good.it1.ss1.ws-0.1" "$good.it1.ss1.wsnan" "$good.it1.ss1.wsinf" \
        "$good.it1.ss1.ws1e-1" "$good.it1.ss1.ws0x1" "$good.it1.ss1.ws" "$good.it1.ss1.ws0.5.5" \
        "$good.it1.ss1.ws 0.5" "$good.it1.ss1.WS0.5" "$good.it1.ws0.5" "$good.it1.ss1.ws1.0001" \
        mass_ratio. mass_ratio.7.pgs.baumgarte mass_ratio.10.pgs mass_ratio.10.jacobi.avbd \
        mass_ratio.10.pgs.baumgarte.x mass_ratio.1e1.pgs.baumgarte pendulum_wave.references \
        nosuch.energy .energy intersecting_stack.Energy intersecting_stack.energy.x ;;
    out_glb)  # not a .glb path that can be written as a new file
      printf '%s\n' "" file file/s.glb adir .glb s.png s.GLB /dev/null . ;;
    out_hdf5)  # not a .hdf5 path that can be written as a new file (file.hdf5: a foreign one)
      printf '%s\n' "" file file/s.hdf5 adir .hdf5 s.h5 s.HDF5 /dev/null . file.hdf5 ;;
    out_json)  # cannot be written as a new scene file
      printf '%s\n' "" file file/s.json adir /dev/null . ;;
    seed)  # a decimal integer in [0, 2^64 - 1] (and only for the random scene)
      printf '%s\n' "" x -1 1.5 1e3 0x10 " 1" "1 " 18446744073709551616 99999999999999999999999 ;;
    shard)  # I/N: whole numbers, 1 <= I <= N <= 100000, or 'slurm' in a Slurm array task
      printf '%s\n' "" 1 / 1/ /3 0/3 4/3 -1/3 1/0 1/-3 1/100001 1/3/ 1//3 a/3 1/b +1/3 " 1/3" \
        "1/3 " 1.5/3 1e0/3 0x1/3 3/3.0 4294967297/4294967298 nan/3 SLURM ;;
    family)  # a scaled scene family's name (stack, pyramid, funnel, pendulum_wave, pendulum_grid)
      printf '%s\n' "" nosuch STACK "stack " " stack" stack_N stack_1 random paper all stack,funnel ;;
    sizes)  # comma-separated sizes, at least two different, each in the family's range (stack: 1..40)
      printf '%s\n' "" , x -1 0 1.5 1e3 0x10 " 1" "1 " "1;2" nan 1 1,1 41 1,41 1000001 4294967297 \
        1,,2 1,2, ,1,2 +1,2 1,2x ;;
    merge)  # folders holding report CSVs
      printf '%s\n' "" nosuch file file/sub adir /dev/null ;;
    scene_one | scene_many | scene_figure | scene_report | scene_bench)
      printf '%s\n' "" nosuch STACK "stack " " stack" stack,funnel stack_0 stack_41 stack_ \
        _1 stack_1x stack_0x10 stack_-1 pyramid_20001 pyramid_0000001 pyramid_4294967297 \
        pendulum_grid_101 funnel_1e3 - \
        nosuch.json adir.json bad.json notjson.json file random_x random_-1 random_07 \
        random_18446744073709551616
      case $kind in
        scene_one) printf '%s\n' all stress paper ;;
        scene_many) printf '%s\n' paper ;;
        scene_figure) printf '%s\n' all stress ;;
        scene_report) printf '%s\n' paper PUSH pushes 'push ' ;;
      esac ;;
    *) echo "bad-input-sweep: no bad values for kind '$kind'" >&2; exit 3 ;;
  esac
}
range_ends() {  # MIN MAX EXCL -> just outside each end: below MIN (MIN itself when it is
  # excluded), above MAX
  awk -v lo="$1" -v hi="$2" -v excl="$3" 'BEGIN {
    if (excl == 1) { print lo; print "-0"; print "1e-400" }
    else if (lo == 0) print "-1e-9"
    else printf "%.17g\n", lo - (lo < 0 ? -lo : lo) / 10
    if (hi != "inf") { printf "%.17g\n", hi + 1; printf "%.17g\n", hi * 2 }
  }'
}
seq_csv() {  # N -> 0,1,...,N-1
  local i s=0
  for ((i = 1; i < $1; i++)); do s+=",$i"; done
  printf '%s' "$s"
}

# Command lines that are bad only in combination, and option conflicts; each "NEEDLES|ARGS"
# with ARGS split on spaces (NEEDLES: what the message must name, alternatives separated by
# '/'). Run only when the command exists (render and figure need the renderer).
EXTRA=(
  "steps/--seconds/--dt|simulate stack --seconds 1e5 --dt 1e-6"
  "--solver-error|simulate stack --seconds 0.1 --at 1"
  "--solver-error|simulate stack --seconds 0.1 --sweeps 1"
  "--trace/--solver-error|simulate stack --seconds 0.1 --trace e.csv --solver-error e.csv"
  "frames/--fps/--seconds|render stack --seconds 1e5 --fps 1000 --size 16x16 --out out"
  "GiB/--size|render stack --seconds 1e5 --fps 0.5 --size 8192x8192 --out out"
  "--size/--compare|render stack --size 16x16 --compare push --seconds 0.1 --fps 10 --out out"
  "--size/--label|render stack --label --seconds 0.1 --fps 10 --size 32x32 --out out"
  "--compare|render stack --compare push --push split --seconds 0.1 --fps 10 --size 64x16 --out out"
  "--eye/--target|render stack --eye 1,2,3 --target 1,2,3 --seconds 0.1 --fps 10 --size 16x16 --out out"
  "--eye/--target|figure stack --eye 0,1,0 --target 0,1,0 --times 0 --size 16x16 --out out/f.png"
  "frames/--speed|render stack --seconds 10 --fps 1000 --speed 0.01 --size 16x16 --out out"
  "--times|figure paper --times 0,1"
  "--compare|figure paper --compare push"
  "--out/file|figure paper --size 16x16 --out file"
  "--out/file|figure paper --size 16x16 --out file/sub"
  "--out/null|figure paper --size 16x16 --out /dev/null"
  "--times/--size/16384|figure stack --times 0,1,2 --size 8192x16 --out out/f.png"
  "--compare|figure stack --compare push --push split --times 0 --size 16x16 --out out/f.png"
  "--compare/--beta|render stack --compare beta=0.1,0.2 --beta 0.3 --seconds 0.1 --fps 10 --size 64x16 --out out"
  "--size/--compare|render stack --compare beta=0,0.2,0.4,0.6 --seconds 0.1 --fps 10 --size 16x64 --out out"
  "--overlay|render stack --overlay --seconds 0.1 --fps 10 --size 16x16 --out out"
  "--overlay|figure stack --overlay --times 0 --size 16x16 --out out/f.png"
  "--overlay|figure paper --overlay"
  "steps/--times/--dt|figure stack --times 0,1e5 --dt 1e-6 --size 16x16 --out out/f.png"
  "--trace/adir|simulate stack --seconds 0.1 --trace adir --force"
  "--trace/--seconds|simulate stack --seconds 1e5 --trace t.csv"
  "--trace/--max-work|simulate stack --seconds 10 --trace t.csv --max-work 92000"
  "--solver-error/1000|simulate pyramid_100 --seconds 0.1 --solver-error s.csv"
  "--solver-error/--max-work|simulate intersecting_stack --seconds 0.1 --solver-error s.csv --sweeps 1000000 --max-work 1e6"
  "--energy/adir|simulate stack --seconds 0.1 --energy adir --force"
  "--energy/--trace|simulate stack --seconds 0.1 --energy t.csv --trace ./t.csv"
  "--energy-every/--energy|simulate stack --seconds 0.1 --energy-every 2"
  "--energy-every|simulate stack --seconds 1e5 --dt 0.01 --energy e.csv --max-work 1e18"
  "--run/--merge|report --merge $MERGE_SRC --run $RUN_ID --out out"
  "--run/--list-runs|report --list-runs --run $RUN_ID --out out"
  "--shard/--list-runs|report intersecting_stack --list-runs --shard 1/2 --out out"
  "--shard/--run|report intersecting_stack --run $RUN_ID --shard 1/2 --out out"
  "--shard/--merge|report --merge $MERGE_SRC --shard 1/2 --out out"
  "--shard|report push --shard 1/2 --out out"
  "push/--run|report push --run $RUN_ID --out out"
  "push/--merge|report push --merge $MERGE_SRC --out out"
  "push/--list-runs|report push --list-runs --out out"
  "push/--seed|report push --seed 3 --out out"
  "twice|report --merge $MERGE_SRC $MERGE_SRC --out out"
  "--merge/--out|report --merge $MERGE_SRC --out $MERGE_SRC/report"
  "names/bidi.json/U+202E|render names/bidi.json --seconds 0.1 --fps 10 --size 16x16 --out out"
  "names/run.json/run|scene names/run.json --out out/s.json"
  "again in|report --merge $MERGE_SRC $MERGE_DUP --out out"
  "us_per_step: 'nan'|report --merge $MERGE_NAN --out out"
  "--rendering/--quick|bench --rendering=false --quick=junk"
  "samples/--fps/--seconds|export stack --seconds 1e5 --fps 1000 --out out/s.glb"
  "--at/--fclib|export stack --seconds 0.1 --at 1 --out out/s.glb"
  "--fclib/--out|export intersecting_stack --seconds 0.1 --fclib out/s.hdf5 --out out/s.glb"
  "--fclib/--fps|export intersecting_stack --seconds 0.1 --fclib out/s.hdf5 --fps 10"
  "--out/--fclib|export intersecting_stack --seconds 0.1"
  "--fclib/file.hdf5|export intersecting_stack --seconds 0.1 --fclib file.hdf5"
  "--out/prior|diff prior/x prior/x --out prior/x"
  "--out/prior|diff prior/x/frame_000000.png prior/x/frame_000000.png --out prior/x --force"
  "--at/1001|export intersecting_stack --seconds 20 --fclib out/s.hdf5 --at $(seq_csv 1001)"
  # Scene-file paths: another file of the same stem into a folder that holds a/x.json's render
  # (both named), and a command's own input as its output (even with --force).
  "a/x.json/b/x.json|render b/x.json --seconds 0.1 --fps 10 --size 16x16 --out prior"
  "a/x.json/b/x.json|figure b/x.json --times 0 --size 16x16 --out prior/x.png"
  "input/x.json|simulate a/x.json --seconds 0.1 --trace a/x.json --force"
  "input/x.json|scene a/x.json --out a/x.json --force"
  # The work budget (bodies x steps x substeps x iterations, --max-work) and an export's samples
  # x bodies: each refused before any step.
  "--max-work/3.6e+14|simulate stack --push soft --soft-substeps 1000 --iterations 10000 --seconds 1e5"
  "--max-work|simulate pyramid_20000 --seconds 1e5"
  "--tgs-substeps|simulate stack --push tgs --tgs-substeps 1000 --iterations 10000 --seconds 1e5"
  "--xpbd-substeps|simulate stack --push xpbd --xpbd-substeps 1000 --iterations 10000 --seconds 1e5"
  "--max-work/9000|simulate stack --seconds 1 --max-work 8999"
  "--max-work|simulate stack --seconds 0.1 --trace t.csv --max-work 1"
  "--max-work|render stack --seconds 0.1 --fps 10 --size 16x16 --out out --max-work 1"
  "--max-work/3600|render stack --seconds 0.1 --fps 10 --size 300x160 --compare iterations=1,100 --out out --max-work 1000"
  "--max-work|figure stack --times 0,0.1 --size 16x16 --out out/f.png --max-work 1"
  "--max-work|export stack --seconds 0.1 --fps 10 --out out/s.glb --max-work 1"
  "--max-work|report --run $RUN_ID --out out --max-work 1"
  "--max-work|report intersecting_stack --list-runs --out out --max-work 1"
  "--max-work|report intersecting_stack --quick --out out --max-work 1"
  # Within the budget alone, past it with the error run, the warm-up and 5 repeats: 7 x 180.
  "--repeats/1260|report --run $RUN_ID --out out --max-work 1000"
  "--repeats|report push --quick --out out --repeats 7"
  "--max-work|report push --quick --out out --max-work 1"
  "--max-work|bench --quick --scene intersecting_stack --max-work 1"
  "--max-work|bench --quick --growth pyramid --sizes 100,20000 --max-work 1e6"
  "--rendering|bench --quick --growth stack --sizes 1,2 --rendering"
  "--growth|bench --quick --sizes 1,2"
  "MiB/--fps|export funnel_2000 --seconds 99.989 --fps 1000 --out out/f.glb"
  "MiB/--fps|export pendulum_wave_2000 --seconds 4 --fps 1000 --out out/p.glb"
)

# Valid command lines (some at the edges of the ranges): each must exit 0.
CONTROLS=(
  "list"
  "simulate stack --seconds 0.1"
  "simulate stack --seconds 0.1 --solver-error e.csv --at 0,5 --sweeps 0,1000000"
  "simulate stack --seconds 0.0084 --dt 1/60"  # rounds to one step, the fewest a run takes
  "simulate stack --seconds 1/60"
  "simulate stack --seconds 0.1 --energy e.csv --energy-every 10000000 --trace t.csv"
  "simulate stack --seconds 0.1 --dt 1/60 --beta 1e-320 --friction 0 --iterations 10000"
  "report --list-runs --out out"
  "report intersecting_stack --run intersecting_stack.pgs.baumgarte.fixed.it1.ss1.ws0.8 --out out"
  # (The push table's base line, report push --quick --out DIR, a minute or two of CPU, exits 0
  # in the ctest case "cps report push --quick compares every push method ...": not again here.)
  "render stack --seconds 0.1 --fps 10 --size 16x16 --out out"
  "render ./b/../a/x.json --seconds 0.1 --fps 10 --size 16x16 --out out"  # '..' in a scene path
  "render $PRIOR/a/x.json --seconds 0.1 --fps 10 --size 16x16 --out out"  # an absolute one
  "render stack --seconds 0.1 --fps 1e-5 --size 16x16 --out out --orbit -36000"
  "figure stack --times 0,0.1 --size 16x16 --out out/f.png"
  "render stack --seconds 0.1 --fps 10 --size 300x160 --compare beta=0,0.5,1 --out out"
  "render stack --seconds 0.1 --fps 10 --size 160x160 --compare dt=1/60,1/120 --overlay --out out"
  "figure stack --times 0 --size 16x16 --compare push --overlay --out out/f.png"
  "export stack --seconds 0.1 --fps 10 --out out/s.glb"
  "export pendulum_grid --seconds 0.1 --fps 1e-5 --out out/p.glb"
  "export intersecting_stack --seconds 0.1 --fclib out/s.hdf5"  # skipped where FCLIB is left out
  "export pendulum_grid --seconds 0.2 --fclib out/p.hdf5 --at 10,11 --force"  # rods: V, R, s
  "simulate stack --seconds 1 --max-work 9000"  # exactly the run's work
  "simulate stack --seconds 0.1 --push soft --soft-substeps 1000 --iterations 10000"
  "simulate stack --seconds 0.1 --push tgs --tgs-substeps 1000 --max-depenetration-speed 1e6"
  "simulate stack --seconds 0.1 --push xpbd --xpbd-substeps 1000 --xpbd-compliance 1e6 --solver jacobi"
  "simulate stack --seconds 0.1 --push avbd --avbd-beta 0 --avbd-alpha 1 --avbd-gamma 0 --avbd-post-iterations 100"
  "report intersecting_stack --list-runs --out out --max-work 1e18"
  "bench --quick --growth stack --sizes 2,1 --friction 0"
  "report intersecting_stack --list-runs --out out --repeats 3"  # the ends of --repeats' range
  "report intersecting_stack --list-runs --out out --repeats 100"
  "report --run $RUN_ID --out out --repeats 3 --max-work 3600"  # exactly (3 + 2) x 720
)

# ---------------------------------------------------------------------------------------------
# Running one command line.

# The memory cap: 1 GiB of address space, unless that breaks a valid command line (a sanitizer
# build maps terabytes of shadow memory; a GL driver may reserve large areas); then 1 GiB of data
# segment (ulimit -d: heap and private writable mappings); if that breaks it too, no rlimit
# but, for a sanitizer build, ASan's own limits (hard_rss_limit_mb, malloc_limit_mb). CAP holds
# bash's ulimit arguments (KiB), set in the subshell that then becomes cps's `timeout`: a
# prlimit process a line would cost an exec more.
CAP=(-v $((MEM / 1024)))
capped() {  # ARGS...: exec timeout ARGS... under the cap (in a subshell: the cap stays there)
  ((${#CAP[@]} == 0)) || ulimit "${CAP[@]}" || exit 126
  exec timeout "$@"
}
cap_works() {  # runs the first control (and a render if there is one) under the cap
  local d=$root/probe line
  for line in "list" "render stack --seconds 0.05 --fps 10 --size 16x16 --out out"; do
    [[ $line == render* ]] && ! "$CPS" render --help > /dev/null 2>&1 && continue
    rm -rf "$d" && mkdir -p "$d"
    # shellcheck disable=SC2086
    { (cd "$d" && capped "$TIMEOUT" "$CPS" $line > /dev/null 2> "$d.err"); } \
      2> /dev/null || return 1
  done
}
choose_cap() {
  if cap_works; then
    MEM_NOTE="address space <= 1 GiB (ulimit -v)"
    return
  fi
  local why
  why=$(head -c 300 "$root/probe.err")
  CAP=()
  if ! cap_works; then  # not the cap's doing: keep it, the controls will show the failure
    CAP=(-v $((MEM / 1024)))
    MEM_NOTE="address space <= 1 GiB (ulimit -v; a valid run fails even without it: $why)"
    return
  fi
  CAP=(-d $((MEM / 1024)))
  if cap_works; then
    MEM_NOTE="data segment <= 1 GiB (ulimit -d: -v of 1 GiB broke a valid run: $why)"
    return
  fi
  CAP=()
  export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}hard_rss_limit_mb=1024:malloc_limit_mb=1024"
  MEM_NOTE="no rlimit (-v and -d broke a valid run: $why); ASan limits 1 GiB if ASan"
}

# Runs "$@" as cps's arguments in the case folder; sets RC, OUT, ERR, WROTE (what was written).
# The fixture is made once per folder and made again only after a command line changed it (a
# failure, or a control that wrote its output), so every line starts from the same fixture.
CASE_DIR=$root/case
FIXTURE_DIR='' FIXTURE_SNAP=''  # the folder whose fixture is intact, and its snapshot
BOMB_PNG='\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x01\x86\xa0\x00\x01\x86\xa0'
BOMB_PNG+='\x08\x02\x00\x00\x00\x27\x30\x9c\x9f\x00\x00\x00\x08\x49\x44\x41\x54\x78\x9c\x03\x00\x00\x00'
BOMB_PNG+='\x00\x01\x48\x06\x89\xd2\x00\x00\x00\x00\x49\x45\x4e\x44\xae\x42\x60\x82'
make_fixture() {  # DIR: a fresh cwd and tmp with the fixture files
  local d=$1
  rm -rf "$d"
  mkdir -p "$d/cwd/adir" "$d/cwd/dir.png" "$d/cwd/adir.json" "$d/tmp"
  printf '{"bodies": [{"shape": "box", "mass_kg": 1}]}\n' > "$d/cwd/bad.json"  # no half_extents_m
  printf 'not json\n' > "$d/cwd/notjson.json"
  mkdir -p "$d/cwd/a" "$d/cwd/b"
  printf '%s\n' "$DROP" > "$d/cwd/a/x.json"
  printf '%s\n' "$DROP" > "$d/cwd/b/x.json"
  [[ ! -d $PRIOR/out ]] || cp -a "$PRIOR/out" "$d/cwd/prior"
  printf 'not written by cps\n' > "$d/cwd/file"
  printf 'not a png, not written by cps\n' > "$d/cwd/file.png"
  printf 'not an FCLIB file, not written by cps\n' > "$d/cwd/file.hdf5"
  # PNG inputs cps must not open or must refuse: a FIFO, a link loop, a 65-byte PNG declaring
  # 100000 x 100000 pixels.
  mkfifo "$d/cwd/fifo.png"
  ln -s loop.png "$d/cwd/loop.png"
  printf "$BOMB_PNG" > "$d/cwd/bomb.png"
  # Scene files whose outputs would be named with a bidi control or as cps's own run.json.
  mkdir -p "$d/cwd/names"
  printf '{"bodies": [], "name": "ab\\u202ecd"}\n' > "$d/cwd/names/bidi.json"
  printf '{"bodies": []}\n' > "$d/cwd/names/run.json"
  FIXTURE_DIR=$d
  snapshot "$d"
  FIXTURE_SNAP=$SNAP
  stamp "$d"
}
# DIR: FIXTURE_PATHS (every path of FIXTURE_SNAP) and DIR/stamp, whose time every later write
# passes. A new, removed or renamed path changes its folder's time, a written file its own, so a
# line changed the fixture only if one of these paths is newer than the stamp (bash's -nt, to the
# nanosecond): the test forks nothing. File times come from a clock that moves in ticks of a few
# ms, so the stamp is followed by a wait, after which a write's time is later than the stamp's.
stamp() {
  local line
  FIXTURE_PATHS=()
  while IFS= read -r line; do FIXTURE_PATHS+=("$1/${line%%|*}"); done <<< "$FIXTURE_SNAP"
  : > "$1/stamp"
  sleep 0.05
}
changed() {  # DIR -> true if a path of FIXTURE_PATHS is newer than DIR/stamp
  local p
  for p in "${FIXTURE_PATHS[@]}"; do [[ $p -nt $1/stamp ]] && return 0; done
  return 1
}
# A command line costs only cps's processes (the subshell that becomes timeout, and cps): a fork
# costs milliseconds here, and the sweep runs thousands of lines, so no $(...) on the way, and
# the snapshot's find runs only when a path of the fixture is newer than its stamp.
run_cps() {
  local d=$CASE_DIR
  [[ $FIXTURE_DIR == "$d" ]] || make_fixture "$d"
  local back=$PWD
  cd "$d/cwd" || exit 3
  (export TMPDIR="$d/tmp"; capped -k 5 "$TIMEOUT" "$CPS" "$@") > "$d/out" 2> "$d/err"
  RC=$?
  cd "$back" || exit 3
  OUT='' ERR=''
  IFS= read -r -d '' -N 4000 OUT < "$d/out"
  IFS= read -r -d '' -N 4000 ERR < "$d/err"
  WROTE=
  changed "$d" || return
  snapshot "$d"
  if [[ $SNAP == "$FIXTURE_SNAP" ]]; then stamp "$d"; return; fi
  # Something changed: what is new or changed (by path), or else what is gone.
  local line gone=
  while IFS= read -r line; do
    [[ $NL$FIXTURE_SNAP$NL == *"$NL$line$NL"* ]] || WROTE+="${WROTE:+, }${line%%|*}"
  done <<< "$SNAP"
  while IFS= read -r line; do
    [[ $NL$SNAP$NL == *"$NL$line$NL"* ]] || gone+="${gone:+, }${line%%|*}"
  done <<< "$FIXTURE_SNAP"
  if [[ -z $WROTE$gone ]]; then stamp "$d"; return; fi  # the same paths, in another order
  FIXTURE_DIR=  # made again before the next command line
  [[ -n $WROTE ]] || WROTE="(removed $gone)"
  local -a paths
  IFS=, read -ra paths <<< "$WROTE"
  ((${#paths[@]} > 3)) && WROTE="${paths[0]},${paths[1]},${paths[2]} and $((${#paths[@]} - 3)) more"
}
snapshot() {  # DIR -> SNAP: every path below DIR/cwd and DIR/tmp (as cwd/... and tmp/...), with the
  # size and time of each that is not a folder
  local back=$PWD
  cd "$1" || exit 3
  find cwd tmp -type d -printf '%p\n' -o -printf '%p|%s|%T@\n' > snap
  cd "$back" || exit 3
  SNAP=''
  IFS= read -r -d '' SNAP < "$1/snap"
}

# WHY: why the last run (of a bad command line) is not a clean refusal, or empty if it is.
# $1: what the message must name, alternatives separated by '/' (those under 2 characters ignored).
verdict_bad() {
  local needles=$1 n named=0
  WHY=
  if ((RC == 124 || RC == 137)); then WHY="timeout: still running after ${TIMEOUT} s"; return; fi
  if ((RC > 128)); then WHY="killed by signal $((RC - 128)) ($(kill -l $((RC - 128)) 2> /dev/null))"; return; fi
  if [[ $ERR == *bad_alloc* || $ERR == *"out of memory"* || $ERR == *"Cannot allocate"* ]]; then
    WHY="memory exhausted (exit $RC)"; return
  fi
  if ((RC == 0)); then WHY="accepted (exit 0)${WROTE:+; wrote $WROTE}"; return; fi
  if ((RC != 2)); then WHY="exit $RC, not 2${WROTE:+; wrote $WROTE}"; return; fi
  if [[ -n $WROTE ]]; then WHY="exit 2 but wrote $WROTE"; return; fi
  local IFS=/
  for n in $needles; do
    ((${#n} >= 2)) && [[ $ERR == *"$n"* ]] && named=1
  done
  ((named)) || WHY="exit 2 but the message does not name ${needles//\// or }"
}

message() {  # STDERR -> MSG: its first line that starts with "cps", else its last line
  local line last=
  while IFS= read -r line; do
    [[ $line == cps* ]] && { MSG=$line; return; }
    [[ -n $line ]] && last=$line
  done <<< "$1"
  MSG=${last:-(nothing on stderr)}
}
quoted() {  # ARGS... -> Q: " ARG1 ARG2 ..." quoted for the shell (eval "args=(...)" reads it back)
  local a q
  Q=
  for a in "$@"; do
    printf -v q '%q' "$a"
    Q+=" $q"
  done
}
show() { quoted "$@"; printf 'cps%s' "$Q"; }  # the command line as a shell would take it

# bad NEEDLES ARGS...: plans a bad command line (run_sweep runs them).
CASE_NEEDLES=() CASE_ARGS=()
bad() {
  CASE_NEEDLES+=("$1")
  shift
  quoted "$@"
  CASE_ARGS+=("$Q")
}
# Runs the planned command lines, JOBS at a time (worker w takes w, w + JOBS, ...), each
# verdict into $root/res/I, then prints the failures in plan order and sets N, P, F.
sweep_worker() {
  local w=$1 i args
  CASE_DIR=$root/w$w
  for ((i = w; i < ${#CASE_ARGS[@]}; i += JOBS)); do
    eval "args=(${CASE_ARGS[i]})"
    run_cps "${args[@]}"
    verdict_bad "${CASE_NEEDLES[i]}"
    message "$ERR"
    printf '%s\n%s\n' "$WHY" "$MSG" > "$root/res/$i"
  done
}
run_sweep() {
  local w i why msg
  mkdir -p "$root/res"
  echo "bad-input-sweep: ${#CASE_ARGS[@]} bad command lines, $JOBS at a time"
  for ((w = 0; w < JOBS; w++)); do sweep_worker "$w" & done
  wait
  N=${#CASE_ARGS[@]} P=0 F=0
  FAILURES=()
  for ((i = 0; i < N; i++)); do
    why="no verdict (the worker died)" msg=
    [[ -f $root/res/$i ]] && { IFS= read -r why; IFS= read -r msg; } < "$root/res/$i"
    if [[ -z $why ]]; then
      P=$((P + 1))
      ((VERBOSE)) && echo "ok   cps${CASE_ARGS[i]}$NL    -> $msg"
    else
      F=$((F + 1))
      FAILURES+=("cps${CASE_ARGS[i]}$NL    -> $why; stderr: ${msg:0:240}")
      ((VERBOSE)) && echo "FAIL cps${CASE_ARGS[i]}$NL    -> $why; stderr: ${msg:0:240}"
    fi
  done
}

# ---------------------------------------------------------------------------------------------
# Reading --help.

# parse_help SUB: sets OPTS (one entry per option: "NAMES|TYPE", NAMES comma separated, TYPE
# empty for a flag) and POSITIONALS ("NAME|TYPE"), SUBS for the top level.
parse_help() {
  local sub=$1 section= line rest head token type
  OPTS=() POSITIONALS=() SUBS=()
  local text
  if [[ $sub == top ]]; then text=$("$CPS" --help 2>&1); else text=$("$CPS" "$sub" --help 2>&1); fi
  if [[ -z $text ]]; then echo "bad-input-sweep: cps $sub --help printed nothing" >&2; exit 3; fi
  while IFS= read -r line; do
    case $line in
      Positionals:) section=pos; continue ;;
      Options:) section=opt; continue ;;
      Subcommands:) section=sub; continue ;;
    esac
    [[ $line =~ ^\ \ ([^\ ].*)$ ]] || continue  # an entry: two spaces, then its name
    rest=${BASH_REMATCH[1]}
    head=${rest%%  *}   # the help column starts after two spaces
    token=${head%% *}
    type=${head#"$token"}
    type=${type# }
    type=${type%%Excludes:*}  # CLI11's notes on options that exclude or need others
    type=${type%%Needs:*}
    type=${type%"${type##*[! ]}"}  # trailing spaces
    case $section in
      opt)
        token=${token//\{+([^\}])\}/}  # --rods,--no-rods{false} -> --rods,--no-rods
        OPTS+=("$token|$type") ;;
      pos) POSITIONALS+=("$token|$type") ;;
      sub) SUBS+=("$token") ;;
    esac
  done <<< "$text"
}

kind_of() {  # SUB NAME TYPE -> kind, or nothing (a value shown as {a, b} is a choice)
  local k=${KIND["$1:$2"]:-${KIND["*:$2"]:-}}
  if [[ -z $k && $3 == *\{*\}* ]]; then k=choice; fi
  printf "%s" "$k"
}
long_name() {  # NAMES (comma separated) -> the first --long one
  local n
  for n in ${1//,/ }; do
    if [[ $n == --* ]]; then printf "%s" "$n"; return; fi
  done
  printf "%s" "${1%%,*}"
}
choices_of() {  # TYPE "{a, b}" or "TEXT:{a,b}=a" -> a b
  local t=${1#*\{}
  t=${t%%\}*}
  t=${t//,/ }
  printf '%s' "$t"
}

# ---------------------------------------------------------------------------------------------
# The plan: every command, option and positional from --help, classified before anything runs.

parse_help top
COMMANDS=("${SUBS[@]}")
if ((${#COMMANDS[@]} == 0)); then echo "bad-input-sweep: no commands in cps --help" >&2; exit 3; fi
unclassified=()
for o in "${OPTS[@]}"; do
  long=$(long_name "${o%%|*}")
  [[ -n ${KIND["top:$long"]:-${KIND["*:$long"]:-}} ]] || unclassified+=("cps: option $long")
done
declare -A PLAN_OPTS PLAN_POS
for sub in "${COMMANDS[@]}"; do
  [[ -n ${BASE[$sub]:-} ]] || unclassified+=("command $sub (no base command line in BASE)")
  parse_help "$sub"
  PLAN_OPTS[$sub]=
  for o in "${OPTS[@]}"; do
    names=${o%%|*}
    type=${o#*|}
    long=$(long_name "$names")
    kind=$(kind_of "$sub" "$long" "$type")
    if [[ -z $kind ]]; then
      unclassified+=("cps $sub: option $long ${type:-(a flag)}")
      continue
    fi
    if [[ $kind == flag && -n $type ]] || [[ $kind != flag && $kind != skip && -z $type ]]; then
      unclassified+=("cps $sub: option $long is classified $kind but --help shows '${type:-no value}'")
      continue
    fi
    PLAN_OPTS[$sub]+="$names|$kind|$type$NL"
  done
  PLAN_POS[$sub]=
  for p in "${POSITIONALS[@]}"; do
    name=${p%%|*}
    kind=${KIND["$sub:$name"]:-}
    if [[ -z $kind ]]; then unclassified+=("cps $sub: positional $name"); continue; fi
    PLAN_POS[$sub]+="$name|$kind$NL"
  done
done
# The world parameters' full lists run on WORLD_FULL: it must have every one of them.
for flag in "${!WORLD[@]}"; do
  [[ "$NL${PLAN_OPTS[$WORLD_FULL]:-}" == *"$NL$flag|"* || "${PLAN_OPTS[$WORLD_FULL]:-}" == *",$flag|"* ]] ||
    unclassified+=("world parameter $flag: not an option of cps $WORLD_FULL, where its full list runs")
done
if ((${#unclassified[@]})); then
  echo "bad-input-sweep: --help shows what this sweep does not know how to classify;" \
    "add it to KIND (and BASE), or set WORLD_FULL, in $0:" >&2
  printf '  %s\n' "${unclassified[@]}" >&2
  exit 3
fi

choose_cap
echo "bad-input-sweep: $CPS; ${#COMMANDS[@]} commands (${COMMANDS[*]});" \
  "timeout ${TIMEOUT} s, memory: $MEM_NOTE"

# ---------------------------------------------------------------------------------------------
# Fixture and controls.

CONTROL_FAILS=()
control() {  # ARGS...: must exit 0
  run_cps "$@"
  if ((RC != 0)); then
    CONTROL_FAILS+=("$(show "$@") -> exit $RC: ${ERR:0:300}")
    echo "CONTROL FAILED (valid, must exit 0): $(show "$@") -> exit $RC: ${ERR:0:300}"
  fi
}
# The --merge source: a complete sweep (the intersecting stack's quick one; RUN_ID is one of
# them), so that merging it is valid (a merge with runs missing exits 1).
# A fixture, not a case: it gets its own bound (SWEEP_FIXTURE_TIMEOUT s; every push method of the
# table runs, 5 timed repeats each, and other lines run beside it).
timeout "${SWEEP_FIXTURE_TIMEOUT:-300}" "$CPS" report intersecting_stack --quick --out "$MERGE_SRC" > /dev/null 2>&1
if ! compgen -G "$MERGE_SRC/*.csv" > /dev/null; then
  CONTROL_FAILS+=("cps report intersecting_stack --quick --out DIR wrote no CSV")
  echo "CONTROL FAILED: cps report intersecting_stack --quick --out DIR wrote no CSV"
fi
mkdir -p "$MERGE_DUP" "$MERGE_NAN"
cp "$MERGE_SRC/intersecting_stack.csv" "$MERGE_DUP/copy.csv" 2> /dev/null
awk -F, -v OFS=, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "us_per_step") c = i }
                  NR == 2 { $c = "nan" } NR <= 2' "$MERGE_SRC/intersecting_stack.csv" \
  > "$MERGE_NAN/nan.csv" 2> /dev/null
snapshot_dir() { (shopt -s dotglob nullglob; stat -c '%n|%s|%y' "$1"/*); }
merge_before=$(snapshot_dir "$MERGE_SRC")

has_command() { [[ " ${COMMANDS[*]} " == *" $1 "* ]]; }
# The scene file a/x.json rendered and drawn into out/ (copied into each case's cwd as prior/).
mkdir -p "$PRIOR/a"
printf '%s\n' "$DROP" > "$PRIOR/a/x.json"
(cd "$PRIOR" && timeout "$TIMEOUT" "$CPS" render a/x.json --seconds 0.1 --fps 10 --size 16x16 --out out &&
  if has_command figure; then timeout "$TIMEOUT" "$CPS" figure a/x.json --times 0 --size 16x16 --out out/x.png; fi) \
  > /dev/null 2>&1 || true
# FCLIB is optional: where it was left out, `cps export --help` says so and the --fclib controls
# are skipped (its bad values are still refused, with the options checked first).
has_fclib=1
"$CPS" export --help 2>&1 | grep -q 'left out of this build' && has_fclib=0
for line in "${CONTROLS[@]}"; do
  read -ra words <<< "$line"
  [[ $has_fclib == 0 && " $line " == *" --fclib "* ]] && continue
  has_command "${words[0]}" && control "${words[@]}"
done
control report --merge "$MERGE_SRC" --out merged
# An expected hash: the one simulate prints, and the same in capitals with 0X.
run_cps simulate stack --seconds 0.1 --json
if [[ $OUT =~ \"state_hash\":\ \"([0-9a-f]{16})\" ]]; then
  hash=${BASH_REMATCH[1]}
  control simulate stack --seconds 0.1 --expect-hash "$hash"
  control simulate stack --seconds 0.1 --expect-hash "0X${hash^^}"
else
  CONTROL_FAILS+=("cps simulate stack --seconds 0.1 --json printed no state_hash")
fi
# Self-test: the classifier must call these failures.
SELF_FAILS=()
run_cps simulate stack --seconds 0.1
verdict_bad --seconds; [[ -n $WHY ]] || SELF_FAILS+=("an accepted command line (exit 0) was not a failure")
run_cps simulate stack --seconds 0.1 --expect-hash 0000000000000000
verdict_bad --expect-hash; [[ $WHY == "exit 1"* ]] || SELF_FAILS+=("exit 1 was not a failure")
RC=2 ERR="cps: something" WROTE=
verdict_bad --seconds; [[ -n $WHY ]] || SELF_FAILS+=("a message that names nothing was not a failure")
RC=2 ERR="cps: --seconds: x" WROTE=out
verdict_bad --seconds; [[ -n $WHY ]] || SELF_FAILS+=("a written file was not a failure")
RC=124 ERR= WROTE=
verdict_bad --seconds; [[ -n $WHY ]] || SELF_FAILS+=("a timeout was not a failure")
# A line that overwrites a fixture file is a failure, and the next line gets the fixture again.
run_cps simulate stack --seconds 0.1 --trace file --force
[[ $WROTE == *cwd/file* ]] || SELF_FAILS+=("an overwritten fixture file was not seen (wrote: '$WROTE')")
run_cps list
[[ -z $WROTE && $(< "$CASE_DIR/cwd/file") == "not written by cps" ]] ||
  SELF_FAILS+=("the fixture was not made again after a line changed it")
# A new file in a fixture folder is seen (through the folder's time).
run_cps simulate stack --seconds 0.1 --trace adir/t.csv
[[ $WROTE == *cwd/adir/t.csv* ]] || SELF_FAILS+=("a file written into a fixture folder was not seen (wrote: '$WROTE')")
((${#SELF_FAILS[@]} == 0)) || printf 'SELF-TEST FAILED: %s\n' "${SELF_FAILS[@]}"

# ---------------------------------------------------------------------------------------------
# The sweep.

unique_values() {  # values: each value once, in the order of its first appearance
  local -A seen=()
  local v kept=()
  for v in "${values[@]}"; do
    [[ -n ${seen["x$v"]:-} ]] && continue
    seen["x$v"]=1
    kept+=("$v")
  done
  values=("${kept[@]}")
}
# base_for SUB KEY -> the contexts (';' separated) for an option or positional
base_for() { printf '%s' "${BASE["$1:$2"]:-${BASE[$1]}}"; }
# without OPT VALUED WORDS... -> WORDS with OPT (and its value when VALUED) removed, into W
without() {
  local opt=$1 valued=$2 skip=0 w
  shift 2
  W=()
  for w in "$@"; do
    if ((skip)); then skip=0; continue; fi
    if [[ $w == "$opt" ]]; then ((valued)) && skip=1; continue; fi
    W+=("$w")
  done
}

# The command line alone, and the top level.
bad "subcommand"
bad "--nosuch" --nosuch
bad "--nosuch" --nosuch list
bad "nosuchcommand" nosuchcommand
bad "LIST" LIST
bad "--version" --version=junk
bad "-z" -z

for sub in "${COMMANDS[@]}"; do
  IFS=';' read -ra contexts <<< "${BASE[$sub]}"
  read -ra words <<< "${contexts[0]}"
  # Unknown options and stray positionals.
  bad "--nosuch" "${words[@]}" --nosuch
  bad "--nosuch" "${words[@]}" --nosuch=1
  bad "-z" "${words[@]}" -z
  bad "extra" "${words[@]}" extra
  bad "---" "${words[@]}" ---
  # Options.
  while IFS='|' read -r names kind type; do
    [[ -n $names && $kind != skip ]] || continue
    long=$(long_name "$names")
    needles=${names//,//}
    valued=1
    [[ $kind == flag ]] && valued=0
    IFS=';' read -ra contexts <<< "$(base_for "$sub" "$long")"
    for ctx in "${contexts[@]}"; do
      read -ra words <<< "$ctx"
      without "$long" "$valued" "${words[@]}"
      if ((!valued)); then
        for name in ${names//,/ }; do
          bad "$needles/junk" "${W[@]}" "$name=junk"
        done
        continue
      fi
      # A missing value: at the end, and with '='.
      bad "$needles" "${W[@]}" "$long"
      bad "$needles" "${W[@]}" "$long="
      # Bad values.
      if [[ $kind == choice ]]; then
        mapfile -t values < <(bad_values choice $(choices_of "$type"))
      elif [[ -n ${WORLD[$long]:-} && $sub != "$WORLD_FULL" && $kind == param:* ]]; then
        mapfile -t values < <(bad_values "routed:${kind#param:}")
      else
        mapfile -t values < <(bad_values "$kind")
      fi
      unique_values
      for v in "${values[@]}"; do
        bad "$needles/$v" "${W[@]}" "$long" "$v"
      done
    done
  done <<< "${PLAN_OPTS[$sub]}"
  # Positionals (the first word after the command).
  while IFS='|' read -r name kind; do
    [[ -n $name && $kind != skip ]] || continue  # (diff's frames: covered by reference's values)
    IFS=';' read -ra contexts <<< "$(base_for "$sub" "$name")"
    read -ra words <<< "${contexts[0]}"
    mapfile -t values < <(bad_values "$kind")
    unique_values
    for v in "${values[@]}"; do
      bad "$name/$v" "${words[0]}" "$v" "${words[@]:2}"
    done
  done <<< "${PLAN_POS[$sub]}"
done

for e in "${EXTRA[@]}"; do
  needles=${e%%|*}
  read -ra words <<< "${e#*|}"
  has_command "${words[0]}" && bad "$needles" "${words[@]}"
done

run_sweep
merge_after=$(snapshot_dir "$MERGE_SRC")
if [[ $merge_after != "$merge_before" ]]; then
  CONTROL_FAILS+=("the --merge source folder $MERGE_SRC was changed")
  echo "FAIL: the --merge source folder was changed by the sweep"
fi

# ---------------------------------------------------------------------------------------------
echo
if ((F > 0)); then
  echo "Failures:"
  printf '  %s\n' "${FAILURES[@]}"
fi
controls_ok=$(( ${#CONTROL_FAILS[@]} == 0 && ${#SELF_FAILS[@]} == 0 ))
echo "controls: $((${#CONTROL_FAILS[@]} == 0 ? 1 : 0)) (1 = every valid command line exited 0);" \
  "self-test: $((${#SELF_FAILS[@]} == 0 ? 1 : 0)); $((SECONDS - start_s)) s"
echo "$N command lines: $P refused cleanly, $F failures"
((F == 0 && controls_ok)) || exit 1
