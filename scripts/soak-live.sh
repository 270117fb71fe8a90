#!/usr/bin/env bash
# Live soak of `arview run` on the emulated camera (tests/support/fake_v4l2_device.cpp), into a
# window under Xvfb, with the HUD, --stats and --trajectory (docs/reliability.md, "Round 4: the
# live soak"). Two modes:
#
#   scripts/soak-live.sh long  --map M --scene S --recording R [--seconds 3600] [--out DIR]
#       one session, Ctrl-C after --seconds; resident memory sampled every 10 s (rss.tsv), then
#       the figures: resident memory after the warm-up (first 5 minutes) against its range,
#       latency p50/p99 of the first and last 10 minutes (from stats.json's frames).
#   scripts/soak-live.sh short --map M --scene S --recording R [--count 200] [--first 1] [--out DIR]
#       --count sessions numbered from --first (a later call goes on where one stopped), of
#       20-60 s each, stopped in turn by SIGINT, SIGTERM and the camera unplugged
#       (ARVIEW_FAKE_CAMERA_UNPLUG_AFTER), into the window and into a video file (video.mp4) in
#       turn, three sessions each (so every stop with every output in six sessions); each
#       checked: the exit status (0 for a signal, 1 and the line naming the unplugged device for
#       an unplug), no core file, no allocator or sanitizer message on stderr, stats.json
#       complete (valid JSON, one record per frame processed), the trajectory a TUM line for at
#       least every localized frame shown, and the video (when it was the output) readable by
#       ffprobe to its end with one frame per frame processed. A failed session's folder is
#       kept, the others' outputs are removed.
#   scripts/soak-live.sh check DIR int|term|unplug
#       the short sessions' check of one session folder again (its output: the file `sink`).
#
# Common options: --arview BIN (default build/release/app/arview), --fake LIB (the emulated
# camera, default build/release/tests/libarview_fake_v4l2.so), --size WxH, --format
# mjpeg|yuyv (default mjpeg), --preload (ARVIEW_FAKE_CAMERA_PRELOAD=1: every payload made at
# STREAMON, so that a loaded machine's camera emulation does not fall behind), --nice N (arview
# at this nice value: on a machine loaded by other work, the tracker's worker thread, 10 above
# the pipeline's, otherwise gets too little CPU to relocalise in time), --heap-check (cheap
# glibc heap-corruption detectors, one per session in turn: MALLOC_CHECK_=3 with
# libc_malloc_debug.so, MALLOC_PERTURB_, tcache off; `long` uses the first), --out DIR
# (default soak-live); after `--`, more options for `arview run` (e.g. `-- --dialogue FILE --mic
# DEV --audio-out DEV`: the dialogue's recognizer and the sound sink's threads). Every session
# runs with `ulimit -c unlimited` in a folder of its own, so that a core file (core_pattern
# "core") lands beside its outputs. Xvfb is started on a free display unless DISPLAY is set.
set -euo pipefail

# Checks session folder $1 stopped by $2; prints one line; returns 1 when anything is wrong.
check_session() {
  python3 - "$1" "$2" <<'EOF'
import json, os, re, sys
d, stop = sys.argv[1], sys.argv[2]
problems, notes = [], []
code = int(open(os.path.join(d, "cmd.code")).read())
err = open(os.path.join(d, "cmd.err"), errors="replace").read()
# The emulated camera silent for 1 s (its producer starved on a loaded machine) ends a session
# as a stalled camera does: exit status 1, the outputs kept, one line. Told apart, not a failure.
stalled = re.search(r"^arview: /dev/video-arview-fake: no frame within", err, re.M) is not None
want = 1 if stop == "unplug" or stalled else 0
if os.path.exists(os.path.join(d, "hang")): problems.append("did not end in time after its stop (a core of it: SIGABRT)")
if code != want: problems.append(f"exit status {code}, {want} expected")
cores = [f for f in os.listdir(d) if f.startswith("core")]
if cores: problems.append("core file " + ", ".join(cores))
if re.search(r"Sanitizer|corrupted|double free|free\(\)|malloc\(\)|malloc_consolidate|Segmentation|Aborted|terminate called", err):
    problems.append("allocator or crash message on stderr")
if stop == "unplug" and not stalled and not re.search(r"^arview: /dev/video-arview-fake: device unplugged", err, re.M):
    problems.append("no error line naming the unplugged device")
frames = localized = -1
try:
    s = json.load(open(os.path.join(d, "stats.json")))
    frames, localized = s["frames_processed"], s["frames_localized"]
    if len(s["frames"]) != frames: problems.append(f"stats.json: {len(s['frames'])} frame records, {frames} processed")
    # A stop during the start-up (a loaded machine's) ends before the first frame, with its
    # outputs written: a note, not a failure.
    if frames == 0: notes.append("stopped before its first frame")
except Exception as e:
    problems.append(f"stats.json: {type(e).__name__}: {e}")
try:
    lines = [l for l in open(os.path.join(d, "traj.txt")) if l.strip() and not l.startswith("#")]
    if any(len(l.split()) != 8 for l in lines): problems.append("traj.txt: a line without 8 fields")
    # Every frame tracked is kept, shown or not: a localized frame dropped before the sink too.
    if localized >= 0 and len(lines) < localized: problems.append(f"traj.txt: {len(lines)} poses, {localized} localized")
except Exception as e:
    problems.append(f"traj.txt: {type(e).__name__}: {e}")
sink_file = os.path.join(d, "sink")
sink = open(sink_file).read().strip() if os.path.exists(sink_file) else "window"
video = os.path.join(d, "video.mp4")
if sink == "video" and frames > 0:
    # Decoded to its end: a file cut short (no index written) or damaged fails here.
    import subprocess
    probe = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                            "stream=nb_read_frames", "-of", "csv=p=0", video], capture_output=True, text=True)
    read = probe.stdout.strip().split(",")[0]
    if probe.returncode != 0 or probe.stderr.strip():
        problems.append(f"video.mp4: ffprobe: {(probe.stderr.strip() or 'exit ' + str(probe.returncode)).splitlines()[0]}")
    elif not read.isdigit() or int(read) != frames:
        problems.append(f"video.mp4: {read} frames, {frames} processed")
elif sink == "video" and os.path.exists(video) and os.path.getsize(video) > 0:
    notes.append("a video of no frame")
print(f"{os.path.basename(d)} {sink} stop={stop}{' (the camera stalled first)' if stalled else ''} exit={code} "
      f"frames={frames} localized={localized}: " +
      ("ok" if not problems else "; ".join(problems)) + "".join(f" ({n})" for n in notes))
sys.exit(1 if problems else 0)
EOF
}

mode=${1:-}
[ "$mode" = long ] || [ "$mode" = short ] || [ "$mode" = check ] || { sed -n '2,/^set -euo/p' "$0" | sed '$d' >&2; exit 2; }
shift
if [ "$mode" = check ]; then
  [ $# = 2 ] || { echo "usage: soak-live.sh check DIR int|term|unplug" >&2; exit 2; }
  check_session "$1" "$2"
  exit
fi
root=$(cd "$(dirname "$0")/.." && pwd)
arview=$root/build/release/app/arview
fake=$root/build/release/tests/libarview_fake_v4l2.so
map="" scene="" recording="" size="" format=mjpeg out=soak-live seconds=3600 count=200 heap_check=0 preload=0 nice=0
first=1 run_args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --arview) arview=$2; shift ;;
    --fake) fake=$2; shift ;;
    --map) map=$2; shift ;;
    --scene) scene=$2; shift ;;
    --recording) recording=$2; shift ;;
    --size) size=$2; shift ;;
    --format) format=$2; shift ;;
    --out) out=$2; shift ;;
    --seconds) seconds=$2; shift ;;
    --count) count=$2; shift ;;
    --first) first=$2; shift ;;
    --heap-check) heap_check=1 ;;
    --preload) preload=1 ;;
    --nice) nice=$2; shift ;;
    --) shift; run_args=("$@"); break ;;
    *) echo "soak-live.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
for f in "$arview" "$fake"; do [ -e "$f" ] || { echo "soak-live.sh: $f does not exist (build it first)" >&2; exit 2; }; done
[ -n "$map" ] && [ -n "$scene" ] && [ -n "$recording" ] || { echo "soak-live.sh: --map, --scene and --recording are needed" >&2; exit 2; }
arview=$(realpath "$arview") fake=$(realpath "$fake") map=$(realpath "$map") scene=$(realpath "$scene")
recording=$(realpath "$recording")
mkdir -p "$out"
out=$(realpath "$out")

xvfb_pid=""
cleanup() { [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null || true; }
trap cleanup EXIT
if [ -z "${DISPLAY:-}" ]; then
  for n in $(seq 80 120); do
    [ -e /tmp/.X11-unix/X$n ] || [ -e /tmp/.X$n-lock ] && continue
    Xvfb ":$n" -screen 0 1920x1080x24 -nolisten tcp >/dev/null 2>&1 &
    xvfb_pid=$!
    export DISPLAY=":$n"
    break
  done
  sleep 2
fi
echo "soak-live.sh: $mode on DISPLAY=$DISPLAY, core_pattern '$(cat /proc/sys/kernel/core_pattern)', $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"

# The heap checker of session number $1 (--heap-check), as environment assignments.
heap_env() {
  [ "$heap_check" = 1 ] || return 0
  local debug=/usr/lib/x86_64-linux-gnu/libc_malloc_debug.so.0
  case $(($1 % 3)) in
    0) echo "MALLOC_CHECK_=3 PRELOAD_EXTRA=$debug" ;;  # glibc 2.34+: MALLOC_CHECK_ needs libc_malloc_debug
    1) echo "MALLOC_PERTURB_=$((($1 * 37) % 255 + 1))" ;;
    2) echo "GLIBC_TUNABLES=glibc.malloc.tcache_count=0" ;;  # every free goes through malloc's own checks
  esac
}

# Runs one session in folder $1 for $2 seconds, stopped by $3 (int, term or unplug), with the
# extra environment $4, into $6 (window or video). Writes cmd.err, cmd.code, sink, stats.json,
# traj.txt (and video.mp4) there; rss.tsv when $5=1.
run_session() {
  local dir=$1 secs=$2 stop=$3 extra=$4 sample_rss=${5:-0} sink=${6:-window}
  mkdir -p "$dir"
  echo "$sink" >"$dir/sink"
  local out_arg=window
  [ "$sink" = video ] && out_arg=video.mp4
  local preload_libs=$fake env_args=() size_args=()
  for kv in $extra; do
    case $kv in
      PRELOAD_EXTRA=*) preload_libs="${kv#PRELOAD_EXTRA=}:$preload_libs" ;;
      *) env_args+=("$kv") ;;
    esac
  done
  [ "$preload" = 1 ] && env_args+=("ARVIEW_FAKE_CAMERA_PRELOAD=1")
  [ "$stop" = unplug ] && env_args+=("ARVIEW_FAKE_CAMERA_UNPLUG_AFTER=$((secs * 30))")
  [ -n "$size" ] && size_args=(--size "$size")
  (
    cd "$dir"
    ulimit -c unlimited
    exec nice -n "$nice" env LD_PRELOAD="$preload_libs" ARVIEW_FAKE_CAMERA_RECORDING="$recording" "${env_args[@]}" \
      "$arview" run --device /dev/video-arview-fake --map "$map" --scene "$scene" --format "$format" "${size_args[@]}" \
      --out "$out_arg" --tracking-worker on --hud --stats stats.json --trajectory traj.txt "${run_args[@]}" \
      >cmd.out 2>cmd.err </dev/null
  ) &
  local pid=$! start=$SECONDS
  if [ "$sample_rss" = 1 ]; then
    printf 'seconds\trss_kib\n' >"$dir/rss.tsv"
    while kill -0 "$pid" 2>/dev/null && [ $((SECONDS - start)) -lt "$secs" ]; do
      sleep 10
      awk -v t=$((SECONDS - start)) '/^VmRSS/ {print t "\t" $2}' "/proc/$pid/status" >>"$dir/rss.tsv" 2>/dev/null || true
    done
  else
    while kill -0 "$pid" 2>/dev/null && [ $((SECONDS - start)) -lt "$secs" ]; do sleep 1; done
  fi
  case $stop in
    int) kill -INT "$pid" 2>/dev/null || true ;;
    term) kill -TERM "$pid" 2>/dev/null || true ;;
  esac
  # 60 s to end after the stop, then it hangs. An unplugged camera ends the session by itself
  # after its frame count, which a loaded machine's emulation reaches late: 2x the session more.
  local waited=0 limit=60
  [ "$stop" = unplug ] && limit=$((60 + 2 * secs))
  while kill -0 "$pid" 2>/dev/null && [ $waited -lt $limit ]; do sleep 1; waited=$((waited + 1)); done
  if kill -0 "$pid" 2>/dev/null; then
    echo "hang" >"$dir/hang"
    kill -ABRT "$pid" 2>/dev/null || true  # a core file of the hang
    sleep 5
  fi
  local code=0
  wait "$pid" || code=$?
  echo "$code" >"$dir/cmd.code"
}

if [ "$mode" = long ]; then
  dir=$out/long
  extra=$(heap_env 0)
  echo "soak-live.sh: one session of $seconds s in $dir ${extra:+($extra)}"
  run_session "$dir" "$seconds" int "$extra" 1
  check_session "$dir" int || true
  python3 - "$dir" <<'EOF'
import json, os, statistics, sys
d = sys.argv[1]
rss = [tuple(map(float, l.split())) for l in open(os.path.join(d, "rss.tsv")).readlines()[1:]]
after = [r / 1024 for t, r in rss if t >= 300]
if after:
    mid = (max(after) + min(after)) / 2
    print(f"resident memory after the first 5 minutes: {min(after):.1f}-{max(after):.1f} MiB "
          f"(±{100 * (max(after) - min(after)) / 2 / mid:.2f}% around {mid:.1f}), at the end {after[-1]:.1f} MiB, "
          f"{len(after)} samples")
s = json.load(open(os.path.join(d, "stats.json")))
frames = s["frames"]
end = frames[-1]["captured_s"]
def window(lo, hi):
    lat = sorted(f["latency_ms"] for f in frames if lo <= f["captured_s"] < hi)
    if not lat: return "no frames"
    p = lambda q: lat[min(len(lat) - 1, int(q * len(lat)))]
    return f"{len(lat)} frames, latency median {statistics.median(lat):.1f} ms, p99 {p(0.99):.1f} ms, max {lat[-1]:.1f} ms"
print(f"{len(frames)} frames over {end:.0f} s; {s['frames_localized']} localized, {s['frames_dropped']} dropped, "
      f"driver dropped {s['source']['driver_dropped']}")
print("first 10 minutes:", window(0, 600))
print("last 10 minutes: ", window(end - 600, end + 1))
EOF
  exit 0
fi

failed=0
stops=(int term unplug)
sinks=(window video)
for i in $(seq "$first" $((first + count - 1))); do
  stop=${stops[$(((i - 1) % 3))]}
  sink=${sinks[$((((i - 1) / 3) % 2))]}
  secs=$((20 + (i * 13) % 41))  # 20-60 s, spread
  dir=$out/session-$(printf %03d "$i")
  extra=$(heap_env "$i")
  run_session "$dir" "$secs" "$stop" "$extra" 0 "$sink"
  if line=$(check_session "$dir" "$stop"); then
    echo "$line ${secs}s ${extra}"
    rm -f "$dir/stats.json" "$dir/traj.txt" "$dir/video.mp4"
  else
    echo "$line ${secs}s ${extra} FAILED"
    failed=$((failed + 1))
  fi
done
echo "soak-live.sh: $count sessions, $failed failed"
[ "$failed" = 0 ]
