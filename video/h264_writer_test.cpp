// The MP4's audio track, read back with FFmpeg's own libraries: a tone written at a known time is
// found there, within one video frame.
#include "video/h264_writer.h"

#include <gtest/gtest.h>
#include <unistd.h>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
}

#include <cmath>
#include <filesystem>
#include <numbers>
#include <vector>

#include "tests/support/test_data.h"
#include "video/video_error.h"

namespace arview::video {
namespace {

namespace fs = std::filesystem;

constexpr int kRate = 16000;
constexpr double kFps = 25.0;

fs::path Scratch(const std::string& name) {
  static const testing::ScratchFolder folder("arview_h264_test");
  return folder.path() / name;
}

std::vector<std::int16_t> Tone(double seconds, double hz = 1000.0) {
  std::vector<std::int16_t> samples(static_cast<std::size_t>(seconds * kRate));
  for (std::size_t i = 0; i < samples.size(); ++i) {
    samples[i] = static_cast<std::int16_t>(std::lround(16000 * std::sin(2 * std::numbers::pi * hz * static_cast<double>(i) / kRate)));
  }
  return samples;
}

struct DecodedAudio {
  int sample_rate = 0;
  int channels = 0;
  double start = 0;            // the first decoded sample's time, s
  std::vector<float> samples;  // the first channel
  double video_seconds = 0;    // the video stream's duration
  std::string codec;
};

// Every audio sample of `file`, each decoded frame placed at its presentation time.
DecodedAudio DecodeAudio(const fs::path& file) {
  DecodedAudio out;
  AVFormatContext* format = nullptr;
  if (avformat_open_input(&format, file.c_str(), nullptr, nullptr) < 0) return out;
  avformat_find_stream_info(format, nullptr);
  const int audio = av_find_best_stream(format, AVMEDIA_TYPE_AUDIO, -1, -1, nullptr, 0);
  const int video = av_find_best_stream(format, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
  if (video >= 0) out.video_seconds = static_cast<double>(format->streams[video]->duration) * av_q2d(format->streams[video]->time_base);
  if (audio < 0) {
    avformat_close_input(&format);
    return out;
  }
  AVStream* stream = format->streams[audio];
  const AVCodec* decoder = avcodec_find_decoder(stream->codecpar->codec_id);
  out.codec = decoder->name;
  AVCodecContext* codec = avcodec_alloc_context3(decoder);
  avcodec_parameters_to_context(codec, stream->codecpar);
  avcodec_open2(codec, decoder, nullptr);
  out.sample_rate = codec->sample_rate;
  out.channels = codec->ch_layout.nb_channels;
  AVPacket* packet = av_packet_alloc();
  AVFrame* frame = av_frame_alloc();
  bool first = true;
  auto drain = [&] {
    while (avcodec_receive_frame(codec, frame) >= 0) {
      const double at = static_cast<double>(frame->best_effort_timestamp) * av_q2d(stream->time_base);
      if (first) {
        out.start = at;
        first = false;
      }
      const auto offset = static_cast<std::size_t>(std::llround((at - out.start) * out.sample_rate));
      if (out.samples.size() < offset + static_cast<std::size_t>(frame->nb_samples)) out.samples.resize(offset + static_cast<std::size_t>(frame->nb_samples), 0.0f);
      const auto* plane = reinterpret_cast<const float*>(frame->data[0]);  // the native decoder gives planar float
      for (int i = 0; i < frame->nb_samples; ++i) out.samples[offset + static_cast<std::size_t>(i)] = plane[i];
    }
  };
  while (av_read_frame(format, packet) >= 0) {
    if (packet->stream_index == audio && avcodec_send_packet(codec, packet) >= 0) drain();
    av_packet_unref(packet);
  }
  avcodec_send_packet(codec, nullptr);
  drain();
  av_frame_free(&frame);
  av_packet_free(&packet);
  avcodec_free_context(&codec);
  avformat_close_input(&format);
  return out;
}

// The time of the first sample louder than `threshold` (full scale 1), or -1.
double Onset(const DecodedAudio& audio, float threshold = 0.1f) {
  for (std::size_t i = 0; i < audio.samples.size(); ++i) {
    if (std::abs(audio.samples[i]) > threshold) return audio.start + static_cast<double>(i) / audio.sample_rate;
  }
  return -1;
}

// `frames` frames of 64x48 at 25 fps, with `clips` (first sample, samples) given before the
// frame at whose time each is due minus `ahead` seconds.
fs::path WriteVideo(const std::string& name, int frames, const std::vector<std::pair<std::int64_t, std::vector<std::int16_t>>>& clips,
                    double ahead = 0.5) {
  const fs::path file = Scratch(name);
  H264Options options;
  options.audio = AudioTrackOptions{};
  auto writer = H264Writer::Open(file, cv::Size(64, 48), kFps, options);
  EXPECT_NE(writer, nullptr);
  std::vector<bool> given(clips.size(), false);
  for (int n = 0; n < frames; ++n) {
    const double t = n / kFps;
    for (std::size_t c = 0; c < clips.size(); ++c) {
      if (!given[c] && static_cast<double>(clips[c].first) / kRate - ahead <= t) {
        writer->WriteAudio(clips[c].first, clips[c].second);
        given[c] = true;
      }
    }
    writer->Write(cv::Mat(48, 64, CV_8UC3, cv::Scalar(n * 3 % 255, 90, 30)));
  }
  writer->Close();
  EXPECT_EQ(writer->AudioSamplesDropped(), 0);
  return file;
}

TEST(H264Writer, AToneWrittenAtAKnownTimeIsHeardThereWithinOneFrame) {
  const double at = 1.3;  // s: between frames 32 and 33
  const fs::path file = WriteVideo("tone.mp4", 75, {{static_cast<std::int64_t>(at * kRate), Tone(0.5)}});
  const DecodedAudio audio = DecodeAudio(file);
  EXPECT_EQ(audio.codec, "aac");
  EXPECT_EQ(audio.sample_rate, kRate);
  EXPECT_EQ(audio.channels, 1);
  const double onset = Onset(audio);
  std::printf("tone written at %.4f s, heard from %.4f s (first sample at %.4f s); video %.3f s, audio %.3f s\n", at, onset,
              audio.start, audio.video_seconds, audio.start + static_cast<double>(audio.samples.size()) / audio.sample_rate);
  EXPECT_NEAR(onset, at, 1.0 / kFps);
  EXPECT_NEAR(audio.start, 0.0, 1.0 / kFps);
  // The tone ends where it should, and the audio covers the whole video.
  double last = -1;
  for (std::size_t i = 0; i < audio.samples.size(); ++i) {
    if (std::abs(audio.samples[i]) > 0.1f) last = audio.start + static_cast<double>(i) / audio.sample_rate;
  }
  EXPECT_NEAR(last, at + 0.5, 1.0 / kFps);
  EXPECT_GE(audio.start + static_cast<double>(audio.samples.size()) / audio.sample_rate, 3.0 - 1.0 / kFps);
}

TEST(H264Writer, TwoClipsKeepTheirDistanceAndAClipGivenLateWithinTheHoldbackStillLands) {
  const double first = 0.6;
  const double second = 2.2;
  // The second clip arrives 0.5 s after its time (within the 1 s holdback).
  const fs::path file = WriteVideo("two.mp4", 100, {{static_cast<std::int64_t>(first * kRate), Tone(0.3)},
                                                    {static_cast<std::int64_t>(second * kRate), Tone(0.3, 500)}}, -0.5);
  const DecodedAudio audio = DecodeAudio(file);
  EXPECT_NEAR(Onset(audio), first, 1.0 / kFps);
  DecodedAudio after = audio;
  const auto cut = static_cast<std::size_t>((first + 0.5 - audio.start) * audio.sample_rate);
  std::fill(after.samples.begin(), after.samples.begin() + static_cast<std::ptrdiff_t>(cut), 0.0f);
  EXPECT_NEAR(Onset(after), second, 1.0 / kFps);
}

TEST(H264Writer, AudioTooLateOrBeforeTheStartIsDroppedAndCounted) {
  const fs::path file = Scratch("late.mp4");
  H264Options options;
  options.audio = AudioTrackOptions{};
  auto writer = H264Writer::Open(file, cv::Size(64, 48), kFps, options);
  ASSERT_NE(writer, nullptr);
  for (int n = 0; n < 50; ++n) writer->Write(cv::Mat(48, 64, CV_8UC3, cv::Scalar(0, 0, 0)));
  // 2 s written, 1 s held back: a clip at 0.5 s is all in written audio; one at -0.1 s loses 1600.
  writer->WriteAudio(8000, Tone(0.1));
  EXPECT_EQ(writer->AudioSamplesDropped(), 1600);
  writer->WriteAudio(-1600, Tone(0.2));
  EXPECT_EQ(writer->AudioSamplesDropped(), 1600 + 3200);  // before 0, and before 1 s: all of it
  EXPECT_THROW(writer->WriteAudio(std::int64_t{kRate} * 3600, Tone(0.1)), VideoError);  // an hour ahead
  writer->Close();
  EXPECT_THROW(writer->WriteAudio(40000, Tone(0.1)), VideoError);
}

TEST(H264Writer, WithoutAnAudioTrackWriteAudioIsRefusedNamingTheFile) {
  const fs::path file = Scratch("silent.mp4");
  auto writer = H264Writer::Open(file, cv::Size(64, 48), kFps);
  ASSERT_NE(writer, nullptr);
  try {
    writer->WriteAudio(0, Tone(0.1));
    FAIL() << "no error";
  } catch (const VideoError& error) {
    EXPECT_EQ(std::string(error.what()), file.string() + ": the video was opened without an audio track");
  }
  writer->Write(cv::Mat(48, 64, CV_8UC3, cv::Scalar(0, 0, 0)));
  writer->Close();
  EXPECT_EQ(DecodeAudio(file).sample_rate, 0);  // no audio stream
}

}  // namespace
}  // namespace arview::video
