// A small MJCF scene for the render tests (a red box "drone" with a free joint over a checker
// floor, two obstacles, cameras "chase" and "onboard"), and RAII holders for mjModel/mjData.
#pragma once

#include <mujoco/mujoco.h>

#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

namespace gbdcs::sim::test {

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

// Loads an MJCF file; fails the calling test (ADD_FAILURE) and returns null on an error.
ModelPtr load_model(const std::filesystem::path& path);
// The test scene, written to a temporary file and loaded.
ModelPtr load_test_scene();
// The team's quadrotor model, or an empty path if it does not exist yet.
std::filesystem::path quadrotor_model_path();

// mj_makeData + mj_forward; the test fails on any MuJoCo warning.
DataPtr make_state(const mjModel* model);
// Shifts the first free joint by (dx, dy, dz) metres and recomputes kinematics.
void move_free_body(const mjModel* model, mjData* data, double dx, double dy, double dz);
// Sets the first free joint's orientation to a yaw of `deg` about world z.
void set_free_body_yaw(const mjModel* model, mjData* data, double deg);
void expect_no_warnings(const mjData* data);

// Centroid (x, y) of the pixels where the channel `dominant` (0 B, 1 G, 2 R) is strong and
// the others are weak; count is the number of such pixels.
struct Blob {
  cv::Point2d centroid;
  int count = 0;
};
Blob find_colour(const cv::Mat& bgr, int dominant);
double grey_stddev(const cv::Mat& bgr);

std::filesystem::path temp_path(const std::string& name);

}  // namespace gbdcs::sim::test
