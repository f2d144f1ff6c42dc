#include "test_scene.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgproc.hpp>

namespace gbdcs::sim::test {
namespace {

constexpr const char* kSceneXml = R"(<mujoco model="render_test">
  <visual><quality offsamples="4"/></visual>
  <asset>
    <texture name="grid" type="2d" builtin="checker" rgb1=".2 .3 .4" rgb2=".8 .8 .8"
             width="256" height="256"/>
    <material name="grid" texture="grid" texrepeat="8 8"/>
  </asset>
  <worldbody>
    <light pos="0 0 4" dir="0 0 -1" diffuse=".8 .8 .8"/>
    <geom name="floor" type="plane" size="10 10 .1" material="grid"/>
    <geom name="pillar" type="box" pos="2.5 0.6 0.5" size=".3 .3 .5" rgba=".1 .2 .9 1"/>
    <geom name="post" type="cylinder" pos="2.5 -0.9 0.5" size=".2 .5" rgba=".1 .8 .1 1"/>
    <camera name="chase" pos="-2 0 1.5" xyaxes="0 -1 0 0.6 0 0.8"/>
    <body name="drone" pos="0 0 0.5">
      <freejoint/>
      <geom name="hull" type="box" size=".1 .1 .03" rgba=".95 .05 .05 1" mass=".08"/>
      <camera name="onboard" pos=".12 0 0" xyaxes="0 -1 0 0 0 1"/>
    </body>
  </worldbody>
</mujoco>
)";

}  // namespace

std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::path(::testing::TempDir()) / name;
}

ModelPtr load_model(const std::filesystem::path& path) {
  char error[1000] = "";
  ModelPtr model(mj_loadXML(path.c_str(), nullptr, error, sizeof error));
  if (!model) {
    ADD_FAILURE() << "cannot load " << path << ": " << error;
  }
  return model;
}

ModelPtr load_test_scene() {
  // One file per process: ctest runs the renderer tests in parallel processes, and with one
  // shared file a test could load another's half-written scene.
  const auto path = temp_path("render_test_scene_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(path) << kSceneXml;
  ModelPtr model = load_model(path);
  std::filesystem::remove(path);
  return model;
}

std::filesystem::path quadrotor_model_path() {
  const std::filesystem::path path =
      std::filesystem::path(GBDCS_SOURCE_DIR) / "sim" / "models" / "quadrotor.xml";
  return std::filesystem::exists(path) ? path : std::filesystem::path();
}

void expect_no_warnings(const mjData* data) {
  for (int i = 0; i < mjNWARNING; ++i) {
    EXPECT_EQ(data->warning[i].number, 0) << "MuJoCo warning " << i;
  }
}

DataPtr make_state(const mjModel* model) {
  DataPtr data(mj_makeData(model));
  mj_forward(model, data.get());
  expect_no_warnings(data.get());
  return data;
}

void move_free_body(const mjModel* model, mjData* data, double dx, double dy, double dz) {
  for (int j = 0; j < model->njnt; ++j) {
    if (model->jnt_type[j] == mjJNT_FREE) {
      const int adr = model->jnt_qposadr[j];
      data->qpos[adr] += dx;
      data->qpos[adr + 1] += dy;
      data->qpos[adr + 2] += dz;
      mj_forward(model, data);
      return;
    }
  }
  ADD_FAILURE() << "the model has no free joint";
}

void set_free_body_yaw(const mjModel* model, mjData* data, double deg) {
  for (int j = 0; j < model->njnt; ++j) {
    if (model->jnt_type[j] == mjJNT_FREE) {
      const int adr = model->jnt_qposadr[j] + 3;
      const double half = deg * mjPI / 360;
      data->qpos[adr] = std::cos(half);
      data->qpos[adr + 1] = 0;
      data->qpos[adr + 2] = 0;
      data->qpos[adr + 3] = std::sin(half);
      mj_forward(model, data);
      return;
    }
  }
  ADD_FAILURE() << "the model has no free joint";
}

Blob find_colour(const cv::Mat& bgr, int dominant) {
  Blob blob;
  double sx = 0;
  double sy = 0;
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
      const int main = p[dominant];
      const int other = std::max(p[(dominant + 1) % 3], p[(dominant + 2) % 3]);
      if (main > 90 && other * 2 < main) {
        sx += x;
        sy += y;
        ++blob.count;
      }
    }
  }
  if (blob.count > 0) {
    blob.centroid = {sx / blob.count, sy / blob.count};
  }
  return blob;
}

double grey_stddev(const cv::Mat& bgr) {
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  cv::Scalar mean;
  cv::Scalar stddev;
  cv::meanStdDev(grey, mean, stddev);
  return stddev[0];
}

}  // namespace gbdcs::sim::test
