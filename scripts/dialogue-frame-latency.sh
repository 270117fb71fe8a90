#!/usr/bin/env bash
# Whether listening and answering slow the frame path (issue 54): `arview run` on the emulated
# camera (tests/support/fake_v4l2_device.cpp) without a dialogue, and with `--dialogue --mic` on
# the emulated microphone (tests/support/emulated.asoundrc: ALSA's `file` plugin, paced by
# arview's capture clock) hearing Debian's pocketsphinx-testdata human recordings, the two in
# turn (off, on, on, off, off, on, ...) so that both see the same load. Each session: Ctrl-C after
# --seconds, --stats written (after one session not counted, which makes the caches); the frames' latency (from the capture timestamp) after the first
# second, per session and over all sessions of each kind. docs/app.md, "The frame path with the
# dialogue on".
#
#   scripts/dialogue-frame-latency.sh --map M --scene S --recording R [--seconds 20] [--pairs 3] [--out DIR]
#
# Options: --arview BIN (default build/release/app/arview), --fake LIB (default
# build/release/tests/libarview_fake_v4l2.so). Into --out null (no window), --audio-out none,
# MJPEG, the tracking worker on. The camera's payloads are made ahead, frame by frame, by the
# emulation on the same cores (not at STREAMON: ARVIEW_FAKE_CAMERA_PRELOAD=1 took longer than a
# session on the loaded machine, and no frame came); both kinds of session carry that load alike.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
arview=$root/build/release/app/arview
fake=$root/build/release/tests/libarview_fake_v4l2.so
map="" scene="" recording="" seconds=20 pairs=3 out=dialogue-frame-latency
while [ $# -gt 0 ]; do
  case $1 in
    --map) map=$2; shift 2 ;;
    --scene) scene=$2; shift 2 ;;
    --recording) recording=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --pairs) pairs=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --arview) arview=$2; shift 2 ;;
    --fake) fake=$2; shift 2 ;;
    *) echo "dialogue-frame-latency.sh: unknown argument '$1' (see the header of $0)" >&2; exit 2 ;;
  esac
done
if [ -z "$map" ] || [ -z "$scene" ] || [ -z "$recording" ]; then
  echo "dialogue-frame-latency.sh: --map, --scene and --recording are needed (see the header of $0)" >&2
  exit 2
fi
testdata=/usr/share/pocketsphinx/test/data
for f in "$arview" "$fake" "$testdata/goforward.raw" "$testdata/cards/001.wav"; do
  [ -e "$f" ] || { echo "dialogue-frame-latency.sh: $f is missing (build arview and arview_fake_v4l2; scripts/install-deps.sh)" >&2; exit 1; }
done
mkdir -p "$out"
out=$(cd "$out" && pwd)

# The microphone's input: the human recordings in turn, 2 s of silence before each, over and over
# for longer than a session (the file plugin gives silence after the file's end). Raw 16 kHz
# 16-bit mono: goforward.raw as it is, the cards' WAVs without their 44-byte header.
spoken=$out/spoken.raw
: >"$spoken"
silence() { head -c $((2 * 16000 * 2)) /dev/zero; }
while [ "$(stat -c %s "$spoken")" -lt $(((seconds + 10) * 32000)) ]; do
  { silence; cat "$testdata/goforward.raw"; for n in 1 2 3 4 5; do silence; tail -c +45 "$testdata/cards/00$n.wav"; done; } >>"$spoken"
done
sed -e "s|@PLAYED@|/dev/null|; s|@PLAYED48@|/dev/null|; s|@SPOKEN@|$spoken|" "$root/tests/support/emulated.asoundrc" >"$out/asoundrc"

# What the character hears and answers: every recording's transcript, a short reply each.
cat >"$out/dialogue.yaml" <<'EOF'
dialogue: 1
personality: {openness: 0.5, conscientiousness: 0.5, extraversion: 0.5, agreeableness: 0.5, neuroticism: 0.5}
decay: 0.05
machines:
  - name: listener
    cyclic: true
    states: [listening, answered]
    final: [answered]
    transitions:
      - from: listening
        to: answered
        when:
          - heard: ["go forward ten meters", "ten of clubs", "four queen of clubs", "seven of clubs", "five five",
                    "eight of spades four of clubs seven of hearts"]
        do:
          - say: <face expr="happy" intensity="0.6"/>I heard you.
          - emotional_influence: {emotion: joy, value: 0.3}
EOF

# Runs one session into folder $1; $2 = on|off.
run_session() {
  local dir=$1 mode=$2 extra=()
  mkdir -p "$dir"
  [ "$mode" = on ] && extra=(--dialogue "$out/dialogue.yaml" --mic arview_mic)
  (
    cd "$dir"
    exec env ALSA_CONFIG_PATH="/usr/share/alsa/alsa.conf:$out/asoundrc" LD_PRELOAD="$fake" \
      ARVIEW_FAKE_CAMERA_RECORDING="$recording" \
      "$arview" run --device /dev/video-arview-fake --map "$map" --scene "$scene" --format mjpeg --out null \
      --audio-out none --tracking-worker on --stats stats.json "${extra[@]}" >cmd.out 2>cmd.err </dev/null
  ) &
  local pid=$! start=$SECONDS
  while kill -0 "$pid" 2>/dev/null && [ $((SECONDS - start)) -lt "$seconds" ]; do sleep 1; done
  kill -INT "$pid" 2>/dev/null || true
  local code=0
  wait "$pid" || code=$?
  echo "$code" >"$dir/cmd.code"
}

# A first session not counted: the caches (the map's descriptor index, the scene's PRT) made.
run_session "$out/warm-up" off
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
# Pairs in the order off-on, on-off, off-on, ...: a drift over the run (the machine's load, the
# emulated camera's producer) then weighs on both kinds alike instead of always on the second.
for i in $(seq 1 "$pairs"); do
  if [ $((i % 2)) = 1 ]; then order="off on"; else order="on off"; fi
  for mode in $order; do run_session "$out/$mode-$i" "$mode"; done
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"

python3 - "$out" "$pairs" <<'EOF'
import json, os, sys
out, pairs = sys.argv[1], int(sys.argv[2])

def pct(v, q):
    v = sorted(v)
    return v[min(len(v) - 1, int(q * (len(v) - 1) + 0.5))] if v else float("nan")

def session(d):
    code = int(open(os.path.join(d, "cmd.code")).read())
    s = json.load(open(os.path.join(d, "stats.json")))
    frames = s["frames"]
    t0 = frames[0]["captured_s"] if frames else 0
    lat = [f["latency_ms"] for f in frames if f["captured_s"] - t0 >= 1.0]
    turns = s.get("dialogue_turns", [])
    heard = [t for t in turns if t.get("heard")]
    return code, lat, len(frames), s.get("frames_localized", 0), len(heard)

kinds = {"off": [], "on": []}
print("session   exit  frames  localized  turns heard  latency median / p95 / p99 ms")
for i in range(1, pairs + 1):
    for k in (("off", "on") if i % 2 else ("on", "off")):
        code, lat, n, loc, heard = session(os.path.join(out, f"{k}-{i}"))
        kinds[k] += lat
        print(f"{k + '-' + str(i):8}  {code:4}  {n:6}  {loc:9}  {heard:11}  {pct(lat, .5):.1f} / {pct(lat, .95):.1f} / {pct(lat, .99):.1f}")
for k in ("off", "on"):
    lat = kinds[k]
    print(f"all {k:3}: {len(lat)} frames, latency median {pct(lat, .5):.1f} ms, p95 {pct(lat, .95):.1f} ms, p99 {pct(lat, .99):.1f} ms")
off, on = kinds["off"], kinds["on"]
if off and on:
    print(f"on / off: median {pct(on, .5) / pct(off, .5):.3f}, p95 {pct(on, .95) / pct(off, .95):.3f}")
EOF
