#include "video/h264_writer.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <cmath>

#include "video/video_error.h"

namespace arview::video {

namespace {

std::string AvErrorText(int error) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {0};
  av_strerror(error, text, sizeof text);
  return text;
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
  bool closed = false;

  ~State() {
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

  // Sends `input` (nullptr: flush) and writes every packet the encoder has ready.
  void Encode(const AVFrame* input) {
    int error = avcodec_send_frame(codec, input);
    if (error < 0) Fail("the H.264 encoder refused a frame", error);
    while (true) {
      error = avcodec_receive_packet(codec, packet);
      if (error == AVERROR(EAGAIN) || error == AVERROR_EOF) return;
      if (error < 0) Fail("the H.264 encoder failed", error);
      av_packet_rescale_ts(packet, codec->time_base, stream->time_base);
      packet->stream_index = stream->index;
      error = av_interleaved_write_frame(format, packet);  // takes the packet's data
      if (error < 0) Fail("cannot write the video", error);
    }
  }
};

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
}

void H264Writer::Close() {
  State& s = *state_;
  if (s.closed) return;
  s.closed = true;
  s.Encode(nullptr);
  const int error = av_write_trailer(s.format);
  if (error < 0) s.Fail("cannot write the file's index", error);
  avio_closep(&s.format->pb);
}

}  // namespace arview::video
