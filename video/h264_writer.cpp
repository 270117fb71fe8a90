#include "video/h264_writer.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/audio_fifo.h>
#include <libavutil/channel_layout.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
#include <libswresample/swresample.h>
#include <libswscale/swscale.h>
}

#include <algorithm>
#include <cmath>
#include <vector>

#include "video/video_error.h"

namespace arview::video {

namespace {

std::string AvErrorText(int error) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {0};
  av_strerror(error, text, sizeof text);
  return text;
}

// The AAC track: clips mixed into `pending` (32-bit sums, one per sample from `written_until`),
// then, once final, converted by libswresample to the encoder's planar float (and its rate, when
// AAC has not the clips' own) and cut into the encoder's frames of 1024 samples.
struct AudioTrack {
  AudioTrackOptions options;
  AVCodecContext* codec = nullptr;
  AVStream* stream = nullptr;
  SwrContext* convert = nullptr;
  AVAudioFifo* fifo = nullptr;
  AVFrame* frame = nullptr;
  std::vector<std::int32_t> pending;
  std::int64_t written_until = 0;   // samples (the clips' rate) handed to the converter
  std::int64_t encoded_frames = 0;  // samples (the encoder's rate) sent to the encoder
  std::int64_t dropped = 0;

  ~AudioTrack() {
    av_frame_free(&frame);
    if (fifo != nullptr) av_audio_fifo_free(fifo);
    swr_free(&convert);
    avcodec_free_context(&codec);
  }
};

// The encoder's rate: the clips' when AAC has it (16 kHz does), else 48 kHz.
int AacRate(const AVCodec* aac, int wanted) {
  if (aac->supported_samplerates == nullptr) return wanted;
  for (const int* rate = aac->supported_samplerates; *rate != 0; ++rate) {
    if (*rate == wanted) return wanted;
  }
  return 48000;
}

}  // namespace

struct H264Writer::State {
  std::string name;
  cv::Size size;
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVStream* stream = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  SwsContext* convert = nullptr;
  int64_t next_pts = 0;
  AVRational frame_rate{0, 1};
  std::unique_ptr<AudioTrack> audio;
  bool closed = false;

  ~State() {
    audio.reset();
    sws_freeContext(convert);
    av_packet_free(&packet);
    av_frame_free(&frame);
    avcodec_free_context(&codec);
    if (format != nullptr) {
      if (format->pb != nullptr) avio_closep(&format->pb);
      avformat_free_context(format);
    }
  }

  [[noreturn]] void Fail(const std::string& what, int error) const {
    throw VideoError(name + ": " + what + " (" + AvErrorText(error) + ")");
  }

  // Sends `input` (nullptr: flush) to `encoder` and writes every packet it has ready to `to`.
  void Encode(AVCodecContext* encoder, AVStream* to, const AVFrame* input, const char* what) {
    int error = avcodec_send_frame(encoder, input);
    if (error < 0) Fail(std::string("the ") + what + " encoder refused a frame", error);
    while (true) {
      error = avcodec_receive_packet(encoder, packet);
      if (error == AVERROR(EAGAIN) || error == AVERROR_EOF) return;
      if (error < 0) Fail(std::string("the ") + what + " encoder failed", error);
      av_packet_rescale_ts(packet, encoder->time_base, to->time_base);
      packet->stream_index = to->index;
      error = av_interleaved_write_frame(format, packet);  // takes the packet's data
      if (error < 0) Fail("cannot write the video", error);
    }
  }
  void Encode(const AVFrame* input) { Encode(codec, stream, input, "H.264"); }

  void OpenAudio(const AudioTrackOptions& options);
  // Converts the pending audio up to sample `until` (the clips' rate) and encodes every full
  // frame; `last`: everything, the final frame short (or padded), then the encoder flushed.
  void FinishAudioUntil(std::int64_t until, bool last);
  void EncodeAudioFrames(bool last);
};

void H264Writer::State::OpenAudio(const AudioTrackOptions& options) {
  if (options.sample_rate < 1000 || options.sample_rate > 384000 || options.bit_rate <= 0 ||
      !(options.holdback_seconds >= 0) || !(options.max_gap_seconds > 0)) {
    Fail("the audio track's options are out of range", AVERROR(EINVAL));
  }
  const AVCodec* aac = avcodec_find_encoder_by_name("aac");
  if (aac == nullptr) Fail("this FFmpeg has no AAC encoder", AVERROR_ENCODER_NOT_FOUND);
  audio = std::make_unique<AudioTrack>();
  AudioTrack& a = *audio;
  a.options = options;
  a.stream = avformat_new_stream(format, nullptr);
  a.codec = avcodec_alloc_context3(aac);
  a.frame = av_frame_alloc();
  if (a.stream == nullptr || a.codec == nullptr || a.frame == nullptr) Fail("out of memory opening the AAC encoder", AVERROR(ENOMEM));
  const int rate = AacRate(aac, options.sample_rate);
  a.codec->sample_fmt = AV_SAMPLE_FMT_FLTP;  // the native encoder's only format
  a.codec->sample_rate = rate;
  a.codec->bit_rate = options.bit_rate;
  a.codec->time_base = AVRational{1, rate};
  av_channel_layout_default(&a.codec->ch_layout, 1);
  if (format->oformat->flags & AVFMT_GLOBALHEADER) a.codec->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  int error = avcodec_open2(a.codec, aac, nullptr);
  if (error < 0) Fail("cannot open the AAC encoder", error);
  error = avcodec_parameters_from_context(a.stream->codecpar, a.codec);
  if (error < 0) Fail("cannot set the audio stream's parameters", error);
  a.stream->time_base = a.codec->time_base;
  AVChannelLayout mono = AV_CHANNEL_LAYOUT_MONO;
  error = swr_alloc_set_opts2(&a.convert, &a.codec->ch_layout, AV_SAMPLE_FMT_FLTP, rate, &mono, AV_SAMPLE_FMT_S16,
                              options.sample_rate, 0, nullptr);
  if (error < 0 || (error = swr_init(a.convert)) < 0) Fail("cannot convert the audio for AAC", error);
  a.fifo = av_audio_fifo_alloc(AV_SAMPLE_FMT_FLTP, 1, a.codec->frame_size > 0 ? a.codec->frame_size : 1024);
  if (a.fifo == nullptr) Fail("out of memory for the audio", AVERROR(ENOMEM));
}

void H264Writer::State::FinishAudioUntil(std::int64_t until, bool last) {
  AudioTrack& a = *audio;
  if (last) until = std::max(until, a.written_until + static_cast<std::int64_t>(a.pending.size()));
  const std::int64_t count = until - a.written_until;
  if (count > 0) {
    std::vector<std::int16_t> final_samples(static_cast<std::size_t>(count), 0);
    const std::size_t held = std::min(final_samples.size(), a.pending.size());
    for (std::size_t i = 0; i < held; ++i) final_samples[i] = static_cast<std::int16_t>(std::clamp(a.pending[i], -32768, 32767));
    a.pending.erase(a.pending.begin(), a.pending.begin() + static_cast<std::ptrdiff_t>(held));
    a.written_until = until;
    const auto* in = reinterpret_cast<const uint8_t*>(final_samples.data());
    const int out_room = swr_get_out_samples(a.convert, static_cast<int>(count));
    std::vector<float> converted(static_cast<std::size_t>(std::max(out_room, 1)));
    auto* out = reinterpret_cast<uint8_t*>(converted.data());
    const int got = swr_convert(a.convert, &out, out_room, &in, static_cast<int>(count));
    if (got < 0) Fail("cannot convert the audio for AAC", got);
    void* planes[1] = {converted.data()};
    if (av_audio_fifo_write(a.fifo, planes, got) < got) Fail("out of memory for the audio", AVERROR(ENOMEM));
  }
  if (last) {
    // What the converter still holds (a resampler's filter tail).
    std::vector<float> tail(4096);
    auto* out = reinterpret_cast<uint8_t*>(tail.data());
    const int got = swr_convert(a.convert, &out, static_cast<int>(tail.size()), nullptr, 0);
    void* planes[1] = {tail.data()};
    if (got > 0 && av_audio_fifo_write(a.fifo, planes, got) < got) Fail("out of memory for the audio", AVERROR(ENOMEM));
  }
  EncodeAudioFrames(last);
}

void H264Writer::State::EncodeAudioFrames(bool last) {
  AudioTrack& a = *audio;
  const int frame_size = a.codec->frame_size > 0 ? a.codec->frame_size : 1024;
  while (av_audio_fifo_size(a.fifo) >= frame_size || (last && av_audio_fifo_size(a.fifo) > 0)) {
    const int take = std::min(frame_size, av_audio_fifo_size(a.fifo));
    // The last frame short where the encoder allows it, else padded with silence.
    const bool short_ok = (a.codec->codec->capabilities & AV_CODEC_CAP_SMALL_LAST_FRAME) != 0;
    const int size = take < frame_size && !short_ok ? frame_size : take;
    av_frame_unref(a.frame);
    a.frame->format = AV_SAMPLE_FMT_FLTP;
    a.frame->sample_rate = a.codec->sample_rate;
    a.frame->nb_samples = size;
    int error = av_channel_layout_copy(&a.frame->ch_layout, &a.codec->ch_layout);
    if (error >= 0) error = av_frame_get_buffer(a.frame, 0);
    if (error < 0) Fail("out of memory for the audio", error);
    std::fill_n(reinterpret_cast<float*>(a.frame->data[0]), size, 0.0f);
    if (av_audio_fifo_read(a.fifo, reinterpret_cast<void**>(a.frame->data), take) < take) Fail("cannot read the audio back", AVERROR(EIO));
    a.frame->pts = a.encoded_frames;
    a.encoded_frames += size;
    Encode(a.codec, a.stream, a.frame, "AAC");
  }
  if (last) Encode(a.codec, a.stream, nullptr, "AAC");
}

H264Writer::H264Writer(std::unique_ptr<State> state) : state_(std::move(state)) {}

H264Writer::~H264Writer() {
  try {
    Close();
  } catch (const VideoError&) {
    // Destruction must not throw; Close() reports the error to a caller that asks.
  }
}

std::unique_ptr<H264Writer> H264Writer::Open(const std::filesystem::path& path, cv::Size size, double fps,
                                             const H264Options& options) {
  const AVCodec* x264 = avcodec_find_encoder_by_name("libx264");
  // 4:2:0 chroma needs an even size; OpenCV's writer copes with odd ones.
  if (x264 == nullptr || size.width <= 0 || size.height <= 0 || size.width % 2 != 0 || size.height % 2 != 0) return nullptr;
  // libx264 prints its statistics at close, and FFmpeg its notes, on stderr: only errors.
  av_log_set_level(AV_LOG_ERROR);
  auto s = std::make_unique<State>();
  s->name = path.string();
  s->size = size;
  int error = avformat_alloc_output_context2(&s->format, nullptr, nullptr, s->name.c_str());
  if (error < 0 || s->format == nullptr) s->Fail("FFmpeg has no container for this file name", error);
  s->stream = avformat_new_stream(s->format, nullptr);
  s->codec = avcodec_alloc_context3(x264);
  s->frame = av_frame_alloc();
  s->packet = av_packet_alloc();
  if (s->stream == nullptr || s->codec == nullptr || s->frame == nullptr || s->packet == nullptr) {
    s->Fail("out of memory opening the encoder", AVERROR(ENOMEM));
  }
  // Frame times in 1/1000 of the frame period's units: any rate, including 29.97, is exact enough.
  const AVRational rate = av_d2q(fps, 100000);
  s->codec->width = size.width;
  s->codec->height = size.height;
  s->codec->pix_fmt = AV_PIX_FMT_YUV420P;
  s->codec->time_base = av_inv_q(rate);
  s->codec->framerate = rate;
  s->codec->thread_count = 1;
  if (s->format->oformat->flags & AVFMT_GLOBALHEADER) s->codec->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  av_opt_set(s->codec->priv_data, "preset", options.preset.c_str(), 0);
  av_opt_set_int(s->codec->priv_data, "crf", options.crf, 0);
  error = avcodec_open2(s->codec, x264, nullptr);
  if (error < 0) s->Fail("cannot open the libx264 encoder", error);
  error = avcodec_parameters_from_context(s->stream->codecpar, s->codec);
  if (error < 0) s->Fail("cannot set the stream's parameters", error);
  s->stream->time_base = s->codec->time_base;
  s->stream->avg_frame_rate = rate;
  s->frame_rate = rate;
  if (options.audio) s->OpenAudio(*options.audio);
  error = avio_open(&s->format->pb, s->name.c_str(), AVIO_FLAG_WRITE);
  if (error < 0) s->Fail("cannot create the file", error);
  error = avformat_write_header(s->format, nullptr);
  if (error < 0) s->Fail("cannot write the file's header", error);

  s->frame->format = AV_PIX_FMT_YUV420P;
  s->frame->width = size.width;
  s->frame->height = size.height;
  error = av_frame_get_buffer(s->frame, 0);
  if (error < 0) s->Fail("out of memory for a frame", error);
  s->convert = sws_getContext(size.width, size.height, AV_PIX_FMT_BGR24, size.width, size.height, AV_PIX_FMT_YUV420P,
                              SWS_BILINEAR, nullptr, nullptr, nullptr);
  if (s->convert == nullptr) s->Fail("no BGR to YUV 4:2:0 conversion", AVERROR(EINVAL));
  return std::unique_ptr<H264Writer>(new H264Writer(std::move(s)));
}

void H264Writer::Write(const cv::Mat& bgr) {
  State& s = *state_;
  if (s.closed) throw VideoError(s.name + ": the video is already closed");
  if (bgr.size() != s.size || bgr.type() != CV_8UC3) throw VideoError(s.name + ": frame is not 8-bit BGR at the opened size");
  int error = av_frame_make_writable(s.frame);  // the encoder may still hold the last one
  if (error < 0) s.Fail("out of memory for a frame", error);
  const uint8_t* source[1] = {bgr.data};
  const int stride[1] = {static_cast<int>(bgr.step[0])};
  sws_scale(s.convert, source, stride, 0, bgr.rows, s.frame->data, s.frame->linesize);
  s.frame->pts = s.next_pts++;
  s.Encode(s.frame);
  if (s.audio) {
    // The audio up to the end of this frame, less the holdback, is final.
    const AudioTrack& a = *s.audio;
    const double video_end = static_cast<double>(s.next_pts) * av_q2d(av_inv_q(s.frame_rate));
    const auto until = static_cast<std::int64_t>(std::floor((video_end - a.options.holdback_seconds) * a.options.sample_rate));
    if (until > a.written_until) s.FinishAudioUntil(until, false);
  }
}

void H264Writer::WriteAudio(std::int64_t first_sample, std::span<const std::int16_t> samples) {
  State& s = *state_;
  if (!s.audio) throw VideoError(s.name + ": the video was opened without an audio track");
  if (s.closed) throw VideoError(s.name + ": the video is already closed");
  AudioTrack& a = *s.audio;
  const auto count = static_cast<std::int64_t>(samples.size());
  const std::int64_t keep_from = std::max(first_sample, a.written_until);
  const std::int64_t end = first_sample + count;
  if (keep_from >= end) {
    a.dropped += count;
    return;
  }
  a.dropped += keep_from - first_sample;
  const auto max_gap = static_cast<std::int64_t>(a.options.max_gap_seconds * a.options.sample_rate);
  if (keep_from - a.written_until > max_gap) {
    throw VideoError(s.name + ": an audio clip at " + std::to_string(static_cast<double>(first_sample) / a.options.sample_rate) +
                     " s starts more than " + std::to_string(static_cast<int>(a.options.max_gap_seconds)) +
                     " s after the audio written (" + std::to_string(static_cast<double>(a.written_until) / a.options.sample_rate) + " s)");
  }
  const auto needed = static_cast<std::size_t>(end - a.written_until);
  if (a.pending.size() < needed) a.pending.resize(needed, 0);
  for (std::int64_t i = keep_from; i < end; ++i) {
    a.pending[static_cast<std::size_t>(i - a.written_until)] += samples[static_cast<std::size_t>(i - first_sample)];
  }
}

std::int64_t H264Writer::AudioSamplesDropped() const { return state_->audio ? state_->audio->dropped : 0; }

void H264Writer::Close() {
  State& s = *state_;
  if (s.closed) return;
  s.closed = true;
  s.Encode(nullptr);
  if (s.audio) {
    // At least up to the last frame's end, and on to the end of the last clip.
    const double video_end = static_cast<double>(s.next_pts) * av_q2d(av_inv_q(s.frame_rate));
    s.FinishAudioUntil(static_cast<std::int64_t>(std::ceil(video_end * s.audio->options.sample_rate)), true);
  }
  const int error = av_write_trailer(s.format);
  if (error < 0) s.Fail("cannot write the file's index", error);
  avio_closep(&s.format->pb);
}

}  // namespace arview::video
