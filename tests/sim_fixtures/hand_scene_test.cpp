#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>
#include <random>

#include "gbdcs/sim/hand_scene.hpp"

namespace gbdcs::sim {
namespace {

// An open palm of the pose library (variant `seed`), facing the camera at `distance_m`.
auto render_open_palm(HandScene& scene, unsigned seed, double distance_m) {
  std::mt19937 rng(seed);
  HandInstance hand;
  hand.pose = pose_for(PoseName::kOpenPalm, rng);
  hand.distance_m = distance_m;
  return scene.render(hand);
}

// The MuJoCo hand's landmark sites, in the hand's own frame, are where the kinematic hand
// of sim/landmarks puts them: the articulated model and the pose library agree joint for
// joint, so a pose from the library renders as the hand it describes.
TEST(HandScene, SitesMatchTheKinematicHandForEveryPose) {
  HandScene scene(160, 120);
  const mjModel* m = scene.model();
  const int hand = mj_name2id(m, mjOBJ_BODY, "hand");
  ASSERT_GE(hand, 0);
  std::mt19937 rng(7);
  for (PoseName name : kAllPoses) {
    for (int variant = 0; variant < 3; ++variant) {
      HandInstance h;
      h.pose = pose_for(name, rng);
      scene.project(h);
      const mjData* d = scene.data();
      const auto expected = hand_points_mm(h.pose);
      const char* names[21] = {"lm_wrist",      "lm_thumb_cmc",  "lm_thumb_mcp",  "lm_thumb_ip",
                               "lm_thumb_tip",  "lm_index_mcp",  "lm_index_pip",  "lm_index_dip",
                               "lm_index_tip",  "lm_middle_mcp", "lm_middle_pip", "lm_middle_dip",
                               "lm_middle_tip", "lm_ring_mcp",   "lm_ring_pip",   "lm_ring_dip",
                               "lm_ring_tip",   "lm_pinky_mcp",  "lm_pinky_pip",  "lm_pinky_dip",
                               "lm_pinky_tip"};
      for (std::size_t i = 0; i < 21; ++i) {
        const int s = mj_name2id(m, mjOBJ_SITE, names[i]);
        ASSERT_GE(s, 0) << names[i];
        double rel[3], local[3];
        for (int c = 0; c < 3; ++c) rel[c] = d->site_xpos[3 * s + c] - d->xpos[3 * hand + c];
        mju_mulMatTVec(local, d->xmat + 9 * hand, rel, 3, 3);
        EXPECT_NEAR(local[0] * 1000, expected[i].x, 0.5) << to_string(name) << " " << names[i];
        EXPECT_NEAR(local[1] * 1000, expected[i].y, 0.5) << to_string(name) << " " << names[i];
        EXPECT_NEAR(local[2] * 1000, expected[i].z, 0.5) << to_string(name) << " " << names[i];
      }
    }
  }
}

TEST(HandScene, ProjectsThePalmCentreWhereItWasPlaced) {
  HandScene scene(320, 240);
  std::mt19937 rng(3);
  HandInstance h;
  h.pose = pose_for(PoseName::kOpenPalm, rng);
  h.pose.orientation = {};
  h.center_x = 0.3;
  h.center_y = 0.6;
  h.distance_m = 0.8;
  const auto p = scene.project(h);
  // Wrist below the palm centre, middle knuckle above it, both near x = 0.3.
  EXPECT_NEAR(p.points[0].x, 0.3, 0.01);
  EXPECT_GT(p.points[0].y, 0.6);
  EXPECT_LT(p.points[9].y, 0.6);
  // Hand length 183 mm at 0.8 m: f * 0.183 / 0.8 pixels.
  const double length_px = std::hypot((p.points[12].x - p.points[0].x) * 320,
                                      (p.points[12].y - p.points[0].y) * 240);
  EXPECT_NEAR(length_px, scene.focal_px() * 0.183 / 0.8, 0.06 * length_px);
}

TEST(HandScene, LeftHandIsTheMirrorImageOfTheRightOne) {
  HandScene scene(320, 240);
  std::mt19937 rng(5);
  HandInstance right;
  // Without an aim (which sim/landmarks applies after the mirroring, so that a left hand
  // points the way it is told) a left hand is exactly the mirror image of a right one.
  right.pose = pose_for(PoseName::kVictory, rng);
  right.pose.orientation.aim_deg = 0;
  right.center_x = 0.4;
  HandInstance left = right;
  left.handedness = contracts::Handedness::kLeft;
  left.center_x = 0.6;
  const auto r = scene.render(right);
  const auto l = scene.render(left);
  for (std::size_t i = 0; i < 21; ++i) {
    EXPECT_NEAR(r.landmarks.points[i].x, 1 - l.landmarks.points[i].x, 1e-6);
    EXPECT_NEAR(r.landmarks.points[i].y, l.landmarks.points[i].y, 1e-6);
  }
  cv::Mat flipped;
  cv::flip(l.mask, flipped, 1);
  EXPECT_EQ(cv::countNonZero(r.mask != flipped), 0);
  EXPECT_GT(cv::countNonZero(r.mask), 500);
}

// The visible hand is one skinned surface: every vertex bound to the hand's bodies, the
// primitives of the skin material hidden (kept for their mass), and the surface follows the
// joints: in a fist and in an open hand every landmark the camera faces lies on drawn skin.
TEST(HandScene, OneSkinCoversTheHandAndFollowsTheJoints) {
  HandScene scene(320, 240);
  const mjModel* m = scene.model();
  ASSERT_EQ(m->nskin, 1);
  EXPECT_GT(m->skin_vertnum[0], 2000);
  EXPECT_GE(m->skin_texcoordadr[0], 0);
  EXPECT_EQ(m->skin_matid[0], mj_name2id(m, mjOBJ_MATERIAL, "skin"));
  std::vector<double> weight(static_cast<std::size_t>(m->skin_vertnum[0]), 0.0);
  for (int b = m->skin_boneadr[0]; b < m->skin_boneadr[0] + m->skin_bonenum[0]; ++b) {
    for (int k = 0; k < m->skin_bonevertnum[b]; ++k) {
      const int i = m->skin_bonevertadr[b] + k;
      weight[static_cast<std::size_t>(m->skin_bonevertid[i])] += m->skin_bonevertweight[i];
    }
  }
  for (double w : weight) ASSERT_NEAR(w, 1.0, 1e-3);
  const int skin = mj_name2id(m, mjOBJ_MATERIAL, "skin");
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_matid[g] == skin) {
      EXPECT_EQ(m->geom_group[g], 3) << mj_id2name(m, mjOBJ_GEOM, g);
    }
  }
  for (auto name : {PoseName::kFist, PoseName::kOpenPalm, PoseName::kPointUp}) {
    std::mt19937 rng(3);
    HandInstance hand;
    hand.pose = pose_for(name, rng);
    hand.distance_m = 0.45;
    const auto r = scene.render(hand);
    int on_skin = 0;
    for (const auto& p : r.landmarks.points) {
      const int x = static_cast<int>(p.x * 320), y = static_cast<int>(p.y * 240);
      if (x >= 0 && x < 320 && y >= 0 && y < 240 && r.mask.at<unsigned char>(y, x) != 0) ++on_skin;
    }
    // A landmark is a joint centre or a pad end: inside the silhouette, or at its edge.
    EXPECT_GE(on_skin, 19) << to_string(name);
  }
}


// The skin is retargeted from the sculpted WebXR hand mesh (ci/fetch-models puts it in the
// build's models folder) so that each finger ends at its tip landmark, as MediaPipe's tips sit at
// the finger's end: just inside the tip there is skin, a little beyond it (along the distal
// phalanx) there is none. (The WebXR tip joint lies mid-pad; mapping it onto our tip made every
// finger about 10 mm too long.)
TEST(HandScene, SculptedFingersEndAtTheirTipLandmarks) {
  ASSERT_NE(default_hand_mesh_path(), "") << "GBDCS_HAND_MESH=generated is set";
  HandScene scene(640, 480);
  constexpr double kDistance = 0.35;
  const auto r = render_open_palm(scene, 3, kDistance);
  const auto& pts = r.landmarks.points;
  auto px = [](const auto& p) { return cv::Point2d(p.x * 640, p.y * 480); };
  auto skin_at = [&](cv::Point2d q) {
    const int x = static_cast<int>(std::lround(q.x)), y = static_cast<int>(std::lround(q.y));
    return x >= 0 && x < 640 && y >= 0 && y < 480 && r.mask.at<unsigned char>(y, x) > 127;
  };
  for (int tip : {8, 12, 16, 20}) {
    const cv::Point2d t = px(pts[tip]), d = px(pts[tip - 1]);
    const cv::Point2d along = (t - d) * (1.0 / std::hypot(t.x - d.x, t.y - d.y));
    const double mm_px = scene.focal_px() * 0.001 / kDistance;  // 1 mm in pixels
    EXPECT_TRUE(skin_at(t - along * (2 * mm_px))) << "landmark " << tip;
    EXPECT_FALSE(skin_at(t + along * (3 * mm_px))) << "landmark " << tip;
  }
}

// A hand mesh that is not a binary glTF, or is cut short, is refused with the file's name and
// the fix; the generated skin stays available.
TEST(HandScene, ABadHandMeshIsAClearError) {
  const std::string bad = testing::TempDir() + "/not_a_hand.glb";
  {
    std::ofstream out(bad, std::ios::binary);
    out << "solid hand\nendsolid\n";
  }
  const std::string cut = testing::TempDir() + "/cut_hand.glb";
  {
    std::ifstream in(default_hand_mesh_path(), std::ios::binary);
    ASSERT_TRUE(in) << default_hand_mesh_path() << " missing: run ci/fetch-models";
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream out(cut, std::ios::binary);
    out << bytes.substr(0, bytes.size() / 2);
  }
  for (const auto& [file, cause] : {std::pair{bad, "not a binary glTF"}, std::pair{cut, "truncated"}}) {
    ::setenv("GBDCS_HAND_MESH", file.c_str(), 1);
    try {
      HandScene scene(160, 120);
      ADD_FAILURE() << file << " was accepted";
    } catch (const std::exception& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(file), std::string::npos) << what;
      EXPECT_NE(what.find(cause), std::string::npos) << what;
      EXPECT_NE(what.find("ci/fetch-models"), std::string::npos) << what;
    }
  }
  ::setenv("GBDCS_HAND_MESH", "generated", 1);
  EXPECT_EQ(default_hand_mesh_path(), "");
  HandScene generated(160, 120);
  EXPECT_EQ(generated.model()->nskin, 1);
  ::unsetenv("GBDCS_HAND_MESH");
}

// Edges are anti-aliased: the hand is drawn at kSupersample times the size and averaged down,
// so its outline has pixels the hand covers only partly (the mask holds the coverage), and
// their colour is the hand's own, not darkened by the black the hand was drawn on.
TEST(HandScene, EdgesAreAntiAliasedWithTheHandsOwnColour) {
  HandScene scene(320, 240);
  const auto r = render_open_palm(scene, 5, 0.5);
  cv::Mat inside = r.mask == 255;
  cv::Mat edge = (r.mask > 0) & (r.mask < 255);
  const int edge_pixels = cv::countNonZero(edge);
  // The outline of an open hand at this size is several hundred pixels long.
  EXPECT_GT(edge_pixels, 200);
  EXPECT_GT(cv::countNonZero(inside), 10 * edge_pixels);
  cv::Mat grey;
  cv::cvtColor(r.bgr, grey, cv::COLOR_BGR2GRAY);
  const double inside_level = cv::mean(grey, inside)[0];
  const double edge_level = cv::mean(grey, edge)[0];
  // The outline turns away from the light, so it is darker than the inside anyway (about 0.7
  // of it); premultiplied by its coverage (about half) it would be about 0.35.
  EXPECT_GT(edge_level, 0.5 * inside_level) << "edge " << edge_level << ", inside " << inside_level;
}

}  // namespace
}  // namespace gbdcs::sim
