#include "gbdcs/adapters/tello_video_decoder.hpp"

#include <stdexcept>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/error.h>
#include <libavutil/frame.h>
#include <libavutil/log.h>
#include <libavutil/imgutils.h>
#include <libswscale/swscale.h>
}

namespace gbdcs::adapters {

namespace {

std::string av_text(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

}  // namespace

struct TelloVideoDecoder::Impl {
  explicit Impl(TelloVideoDecoderOptions o) : options(o) {
    // FFmpeg logs every undecodable packet; they are counted in stats() instead.
    av_log_set_level(AV_LOG_FATAL);
    const AVCodec* codec = avcodec_find_decoder(AV_CODEC_ID_H264);
    if (!codec) {
      throw std::runtime_error(
          "tello video: this FFmpeg (libavcodec) has no H.264 decoder (install Debian's "
          "libavcodec59, see ci/setup)");
    }
    context = avcodec_alloc_context3(codec);
    frame = av_frame_alloc();
    packet = av_packet_alloc();
    if (!context || !frame || !packet) throw std::runtime_error("tello video: out of memory");
    context->flags |= AV_CODEC_FLAG_LOW_DELAY;
    context->thread_count = 1;  // frame threading would hold frames back
    context->max_pixels = options.max_pixels;
    if (const int r = avcodec_open2(context, codec, nullptr); r < 0) {
      throw std::runtime_error("tello video: cannot open the H.264 decoder: " + av_text(r));
    }
  }

  ~Impl() {
    sws_freeContext(scaler);
    av_packet_free(&packet);
    av_frame_free(&frame);
    avcodec_free_context(&context);
  }

  void decode(std::vector<cv::Mat>& out) {
    if (assembled.empty()) return;
    ++stats.encoded_frames;
    // libavcodec reads up to AV_INPUT_BUFFER_PADDING_SIZE bytes past the end: pad with zeros.
    const auto size = assembled.size();
    assembled.resize(size + AV_INPUT_BUFFER_PADDING_SIZE, 0);
    packet->data = assembled.data();
    packet->size = static_cast<int>(size);
    int r = avcodec_send_packet(context, packet);
    av_packet_unref(packet);
    assembled.clear();
    if (r < 0) {
      ++stats.undecodable;
      stats.last_error = av_text(r);
      return;
    }
    receive(out);
  }

  void receive(std::vector<cv::Mat>& out) {
    for (;;) {
      const int r = avcodec_receive_frame(context, frame);
      if (r == AVERROR(EAGAIN) || r == AVERROR_EOF) return;
      if (r < 0) {
        ++stats.undecodable;
        stats.last_error = av_text(r);
        return;
      }
      out.push_back(to_bgr());
      ++stats.frames;
      av_frame_unref(frame);
    }
  }

  cv::Mat to_bgr() {
    const int w = frame->width, h = frame->height;
    scaler = sws_getCachedContext(scaler, w, h, static_cast<AVPixelFormat>(frame->format), w, h,
                                  AV_PIX_FMT_BGR24, SWS_BILINEAR, nullptr, nullptr, nullptr);
    cv::Mat bgr(h, w, CV_8UC3);
    if (!scaler) {
      bgr.setTo(0);
      stats.last_error = "no conversion from the stream's pixel format to BGR";
      return bgr;
    }
    std::uint8_t* planes[4] = {bgr.data, nullptr, nullptr, nullptr};
    int strides[4] = {static_cast<int>(bgr.step[0]), 0, 0, 0};
    sws_scale(scaler, frame->data, frame->linesize, 0, h, planes, strides);
    return bgr;
  }

  TelloVideoDecoderOptions options;
  AVCodecContext* context = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  SwsContext* scaler = nullptr;
  std::vector<std::uint8_t> assembled;
  bool dropping = false;  // the current frame outgrew max_frame_bytes: skip to its end
  TelloVideoDecoderStats stats;
};

TelloVideoDecoder::TelloVideoDecoder(TelloVideoDecoderOptions options)
    : impl_(std::make_unique<Impl>(options)) {}

TelloVideoDecoder::~TelloVideoDecoder() = default;

std::vector<cv::Mat> TelloVideoDecoder::push(std::span<const std::uint8_t> datagram) {
  auto& d = *impl_;
  std::vector<cv::Mat> out;
  ++d.stats.datagrams;
  d.stats.bytes += datagram.size();
  const bool last = datagram.size() < d.options.max_datagram;
  if (!d.dropping) {
    if (d.assembled.size() + datagram.size() > d.options.max_frame_bytes) {
      d.assembled.clear();
      d.dropping = true;
      ++d.stats.oversized;
    } else {
      d.assembled.insert(d.assembled.end(), datagram.begin(), datagram.end());
    }
  }
  if (last) {
    if (d.dropping) {
      d.dropping = false;
    } else {
      d.decode(out);
    }
  }
  return out;
}

std::vector<cv::Mat> TelloVideoDecoder::flush() {
  std::vector<cv::Mat> out;
  if (!impl_->dropping) impl_->decode(out);
  impl_->dropping = false;
  return out;
}

const TelloVideoDecoderStats& TelloVideoDecoder::stats() const { return impl_->stats; }

}  // namespace gbdcs::adapters
