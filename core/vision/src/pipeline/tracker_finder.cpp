// The real HandFinder: MediaPipe Hands through our HandTracker.
#include "gbdcs/vision/hand_tracker.hpp"
#include "gbdcs/vision/vision_pipeline.hpp"

namespace gbdcs::vision {
namespace {

class TrackerHandFinder final : public HandFinder {
 public:
  TrackerHandFinder(const TrackerOptions& options, const contracts::Clock& clock)
      : tracker_(options, clock) {}
  std::vector<contracts::Landmarks> find(const cv::Mat& rgb) override {
    std::vector<contracts::Landmarks> hands;
    for (auto& observation : tracker_.process(rgb)) hands.push_back(observation.landmarks);
    return hands;
  }
  void reset() override { tracker_.reset(); }

 private:
  HandTracker tracker_;
};

}  // namespace

std::unique_ptr<HandFinder> make_tracker_finder(const TrackerOptions& options,
                                                const contracts::Clock& clock) {
  return std::make_unique<TrackerHandFinder>(options, clock);
}

}  // namespace gbdcs::vision
