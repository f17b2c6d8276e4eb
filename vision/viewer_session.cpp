#include "vision/viewer_session.hpp"

#include <stdexcept>

namespace sg::vision {

ViewerSession::ViewerSession(Options options, const StereoCalibration* calibration, Show show)
    : options_(std::move(options)), show_(std::move(show)) {
  state_.calibration = calibration;
}

void ViewerSession::on_image(int camera, int64_t utime, const cv::Mat& image) {
  at(utime).images[camera == 0 ? 0 : 1] = image;
  maybe_draw(utime);
}

void ViewerSession::on_blob(int camera, const stereograsp::blob_t& blob) {
  at(blob.utime).blobs[camera == 0 ? 0 : 1] = blob;
  maybe_draw(blob.utime);
}

void ViewerSession::on_position(const stereograsp::point3_t& position) {
  at(position.utime).position = position;
}

ViewerSession::Entry& ViewerSession::at(int64_t utime) {
  Entry& e = by_utime_[utime];
  while (by_utime_.size() > 60 && by_utime_.begin()->first != utime) {
    by_utime_.erase(by_utime_.begin());  // (never `e` itself: a late oldest frame is kept)
  }
  return e;
}

void ViewerSession::maybe_draw(int64_t utime) {
  const auto it = by_utime_.find(utime);
  if (it == by_utime_.end()) return;
  Entry& e = it->second;
  const bool images = !e.images[0].empty() && !e.images[1].empty();
  const bool blobs = e.blobs[0] && e.blobs[1];
  if (images && (blobs || !options_.wait_for_blobs)) draw(utime, e);
}

void ViewerSession::draw(int64_t utime, Entry& e) {
  state_.images = e.images;
  state_.blobs = e.blobs;
  state_.position = e.position;
  state_.utime = utime;
  recent_.push_back(utime);
  while (recent_.size() > 30) recent_.pop_front();
  if (recent_.size() > 1) {
    state_.frame_rate =
        static_cast<double>(recent_.size() - 1) * 1e6 / double(recent_.back() - recent_.front());
  }
  draw_view(state_, canvas_);
  if (!options_.record.empty()) record(canvas_, utime);
  if (show_) show_(canvas_);
  ++drawn_;
  by_utime_.erase(by_utime_.begin(), by_utime_.upper_bound(utime));
}

void ViewerSession::record(const cv::Mat& canvas, int64_t utime) {
  if (!writer_.isOpened()) {
    writer_.open(options_.record, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), options_.record_fps,
                 canvas.size());
    if (!writer_.isOpened()) throw std::runtime_error(options_.record + ": cannot write the video");
    index_.open(options_.record + ".csv");
    index_ << "video_frame,utime\n";
  }
  writer_.write(canvas);
  index_ << drawn_ << "," << utime << "\n" << std::flush;  // readable while recording
}

}  // namespace sg::vision
