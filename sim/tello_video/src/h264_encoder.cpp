#include "gbdcs/sim/h264_encoder.hpp"

#include <cmath>
#include <stdexcept>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/error.h>
#include <libavutil/frame.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

namespace gbdcs::sim {

namespace {

std::string av_text(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

}  // namespace

struct H264Encoder::Impl {
  explicit Impl(H264EncoderOptions o) : options(o) {
    // FFmpeg's own log lines (per-frame statistics) stay quiet; failures are thrown.
    av_log_set_level(AV_LOG_FATAL);
    if (options.width < 16 || options.height < 16 || options.width % 2 || options.height % 2 ||
        options.width > 4096 || options.height > 2304) {
      throw std::invalid_argument("h264 encoder: width/height must be even, 16...4096 x "
                                  "16...2304 (got " + std::to_string(options.width) + "x" +
                                  std::to_string(options.height) + ")");
    }
    if (!(options.fps > 0 && options.fps <= 120) || options.bitrate_kbps < 50 ||
        options.keyframe_interval < 1) {
      throw std::invalid_argument("h264 encoder: fps must be in (0, 120], bitrate_kbps >= 50, "
                                  "keyframe_interval >= 1");
    }
    const AVCodec* codec = avcodec_find_encoder_by_name("libx264");
    if (!codec) codec = avcodec_find_encoder(AV_CODEC_ID_H264);
    if (!codec) {
      throw std::runtime_error("h264 encoder: this FFmpeg has no H.264 encoder (install "
                               "Debian's libavcodec59 with libx264, see ci/setup)");
    }
    context = avcodec_alloc_context3(codec);
    frame = av_frame_alloc();
    packet = av_packet_alloc();
    if (!context || !frame || !packet) throw std::runtime_error("h264 encoder: out of memory");
    const int rate = static_cast<int>(std::lround(options.fps * 1000));
    context->width = options.width;
    context->height = options.height;
    context->time_base = AVRational{1000, rate};
    context->framerate = AVRational{rate, 1000};
    context->pix_fmt = AV_PIX_FMT_YUV420P;
    context->gop_size = options.keyframe_interval;
    context->max_b_frames = 0;
    context->bit_rate = static_cast<std::int64_t>(options.bitrate_kbps) * 1000;
    context->thread_count = 1;  // the machine is small and the picture too
    if (std::string(codec->name) == "libx264") {
      av_opt_set(context->priv_data, "preset", "ultrafast", 0);
      av_opt_set(context->priv_data, "tune", "zerolatency", 0);
      av_opt_set(context->priv_data, "x264-params", "repeat-headers=1", 0);
    }
    if (const int r = avcodec_open2(context, codec, nullptr); r < 0) {
      throw std::runtime_error("h264 encoder: cannot open " + std::string(codec->name) + ": " +
                               av_text(r));
    }
    frame->format = AV_PIX_FMT_YUV420P;
    frame->width = options.width;
    frame->height = options.height;
    if (const int r = av_frame_get_buffer(frame, 0); r < 0) {
      throw std::runtime_error("h264 encoder: " + av_text(r));
    }
    scaler = sws_getContext(options.width, options.height, AV_PIX_FMT_BGR24, options.width,
                            options.height, AV_PIX_FMT_YUV420P, SWS_BILINEAR, nullptr, nullptr,
                            nullptr);
    if (!scaler) throw std::runtime_error("h264 encoder: no BGR to YUV 4:2:0 conversion");
  }

  ~Impl() {
    sws_freeContext(scaler);
    av_packet_free(&packet);
    av_frame_free(&frame);
    avcodec_free_context(&context);
  }

  H264EncoderOptions options;
  AVCodecContext* context = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  SwsContext* scaler = nullptr;
  std::int64_t pts = 0;
};

H264Encoder::H264Encoder(H264EncoderOptions options)
    : impl_(std::make_unique<Impl>(options)) {}

H264Encoder::~H264Encoder() = default;

std::string H264Encoder::codec_name() const { return impl_->context->codec->name; }

std::vector<std::uint8_t> H264Encoder::encode(const cv::Mat& bgr) {
  auto& d = *impl_;
  if (bgr.type() != CV_8UC3 || bgr.cols != d.options.width || bgr.rows != d.options.height) {
    throw std::invalid_argument("h264 encoder: the image must be CV_8UC3 " +
                                std::to_string(d.options.width) + "x" +
                                std::to_string(d.options.height));
  }
  if (const int r = av_frame_make_writable(d.frame); r < 0) {
    throw std::runtime_error("h264 encoder: " + av_text(r));
  }
  const std::uint8_t* planes[4] = {bgr.data, nullptr, nullptr, nullptr};
  const int strides[4] = {static_cast<int>(bgr.step[0]), 0, 0, 0};
  sws_scale(d.scaler, planes, strides, 0, bgr.rows, d.frame->data, d.frame->linesize);
  d.frame->pts = d.pts++;
  if (const int r = avcodec_send_frame(d.context, d.frame); r < 0) {
    throw std::runtime_error("h264 encoder: " + av_text(r));
  }
  std::vector<std::uint8_t> out;
  for (;;) {
    const int r = avcodec_receive_packet(d.context, d.packet);
    if (r == AVERROR(EAGAIN) || r == AVERROR_EOF) break;
    if (r < 0) throw std::runtime_error("h264 encoder: " + av_text(r));
    out.insert(out.end(), d.packet->data, d.packet->data + d.packet->size);
    av_packet_unref(d.packet);
  }
  return out;
}

std::vector<std::vector<std::uint8_t>> split_datagrams(const std::vector<std::uint8_t>& frame,
                                                       std::size_t max_datagram) {
  if (max_datagram == 0) throw std::invalid_argument("split_datagrams: max_datagram is 0");
  std::vector<std::vector<std::uint8_t>> out;
  for (std::size_t at = 0; at < frame.size(); at += max_datagram) {
    const auto end = std::min(frame.size(), at + max_datagram);
    out.emplace_back(frame.begin() + static_cast<std::ptrdiff_t>(at),
                     frame.begin() + static_cast<std::ptrdiff_t>(end));
  }
  if (!frame.empty() && frame.size() % max_datagram == 0) out.push_back({0});
  return out;
}

}  // namespace gbdcs::sim
