#!/usr/bin/env python3
"""The audio-video offset of a video arview wrote with speech (issue 53, docs/speech.md "Sound").

    scripts/av-offset.py VIDEO.mp4 FRAMES.json

FRAMES.json is `arview say --curves`'s file or a session's --stats file (replay, run, the demo's
<work>/stats.json): per frame of the video, in order, the mouth's opening (`mouth_open`). The video's
audio track is decoded by FFmpeg's command line to 16 kHz mono; its RMS envelope over one frame's
length is cross-correlated (Pearson) with the mouth's opening at lags of -300..+300 ms in 1 ms
steps. Prints the lag of the best match: positive, the sound comes after the mouth. ITU-R BT.1359
allows the sound to lead by at most 45 ms and to lag by at most 125 ms; the exit status is 1 outside
that window. tests/speech_sound_test.cpp does the same on a `say` video.
"""
import json
import math
import struct
import subprocess
import sys

RATE = 16000


def frame_rate(video):
    text = subprocess.run(["ffprobe", "-v", "error", "-select_streams", "v:0", "-show_entries", "stream=avg_frame_rate",
                           "-of", "csv=p=0", video], check=True, capture_output=True, text=True).stdout.strip()
    num, _, den = text.partition("/")
    return float(num) / float(den or 1)


def decoded_audio(video):
    raw = subprocess.run(["ffmpeg", "-v", "error", "-i", video, "-f", "s16le", "-ac", "1", "-ar", str(RATE), "-"],
                         check=True, capture_output=True).stdout
    return struct.unpack("<%dh" % (len(raw) // 2), raw[: len(raw) // 2 * 2])


def mouth_curve(frames_json):
    with open(frames_json) as f:
        frames = json.load(f)["frames"]
    return [float(frame.get("mouth_open", 0.0)) for frame in frames]


def pearson(x, y):
    n = len(x)
    mx, my = sum(x) / n, sum(y) / n
    sxy = sum((a - mx) * (b - my) for a, b in zip(x, y))
    sxx = sum((a - mx) ** 2 for a in x)
    syy = sum((b - my) ** 2 for b in y)
    return sxy / math.sqrt(sxx * syy) if sxx > 0 and syy > 0 else 0.0


def best_lag_ms(mouth, audio, fps):
    squares = [0.0]
    for s in audio:
        squares.append(squares[-1] + float(s) * s)

    def envelope(t):
        i0 = max(0, round((t - 0.5 / fps) * RATE))
        i1 = min(len(audio), round((t + 0.5 / fps) * RATE))
        return math.sqrt((squares[i1] - squares[i0]) / (i1 - i0)) if i1 > i0 else 0.0

    best = (-2.0, 0)
    for lag in range(-300, 301):
        r = pearson(mouth, [envelope(i / fps + lag / 1000.0) for i in range(len(mouth))])
        best = max(best, (r, lag))
    return best[1], best[0]


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    video, frames_json = sys.argv[1], sys.argv[2]
    fps = frame_rate(video)
    mouth = mouth_curve(frames_json)
    audio = decoded_audio(video)
    lag, r = best_lag_ms(mouth, audio, fps)
    print("%s: %d frames at %.3f fps, %.2f s of audio; the sound %s the mouth by %d ms (correlation %.3f); "
          "ITU-R BT.1359 allows -45..+125 ms" % (video, len(mouth), fps, len(audio) / RATE,
                                                 "lags" if lag >= 0 else "leads", abs(lag), r))
    sys.exit(0 if -45 <= lag <= 125 else 1)


if __name__ == "__main__":
    main()
