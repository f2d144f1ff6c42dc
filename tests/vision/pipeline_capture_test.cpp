// Capture sources: images folder, video file, generator, and open_source's errors. Every
// input is made here, in a temporary folder.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "gbdcs/vision/capture.hpp"
#include "pipeline_fakes.hpp"

namespace gbdcs::vision {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing::solid;

class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            ("gbdcs_capture_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const CaptureError& e) {
    return e.what();
  }
  return "(no CaptureError)";
}

TEST(ImageFolderSource, ReadsTheImagesSortedByNameAndStampsThem) {
  TempDir dir;
  // Written out of order, with a file that is not an image.
  cv::imwrite((dir.path() / "b.png").string(), solid(8, 6, {0, 0, 200}));  // BGR: red
  cv::imwrite((dir.path() / "a.png").string(), solid(8, 6, {200, 0, 0}));  // BGR: blue
  cv::imwrite((dir.path() / "c.PNG").string(), solid(4, 4, {0, 200, 0}));
  std::ofstream(dir.path() / "notes.txt") << "not an image";

  contracts::ManualClock clock;
  auto source = open_source("images:" + dir.path().string(), clock);
  EXPECT_FALSE(source->live());
  EXPECT_EQ(source->describe(), "images:" + dir.path().string());

  std::vector<std::string> names;
  for (int i = 0; i < 3; ++i) {
    clock.advance(10ms);
    auto f = source->next();
    ASSERT_TRUE(f);
    EXPECT_EQ(f->frame_id, i);
    EXPECT_EQ(f->capture_time, std::chrono::milliseconds(10 * (i + 1)));
    EXPECT_EQ(f->capture_utc, clock.utc_now());
    EXPECT_EQ(f->order, PixelOrder::kBgr);
    EXPECT_EQ(f->rgb.type(), CV_8UC3);
    names.push_back(fs::path(f->source).filename().string());
    const cv::Vec3b expected = i == 0   ? cv::Vec3b(200, 0, 0)
                               : i == 1 ? cv::Vec3b(0, 0, 200)
                                        : cv::Vec3b(0, 200, 0);
    EXPECT_EQ(f->rgb.at<cv::Vec3b>(0, 0), expected);
  }
  EXPECT_EQ(names, (std::vector<std::string>{"a.png", "b.png", "c.PNG"}));
  EXPECT_EQ(source->next(), std::nullopt);
}

TEST(ImageFolderSource, EmptyOrMissingFolderIsAClearError) {
  TempDir dir;
  contracts::ManualClock clock;
  auto empty = error_of([&] { open_source("images:" + dir.path().string(), clock); });
  EXPECT_NE(empty.find("images:" + dir.path().string()), std::string::npos) << empty;
  EXPECT_NE(empty.find("no images"), std::string::npos) << empty;

  auto missing = error_of([&] { open_source("images:" + (dir.path() / "nope").string(), clock); });
  EXPECT_NE(missing.find("nope"), std::string::npos) << missing;
  EXPECT_NE(missing.find("not a folder"), std::string::npos) << missing;
}

TEST(ImageFolderSource, AnUndecodableImageNamesTheFile) {
  TempDir dir;
  std::ofstream(dir.path() / "broken.jpg") << "these bytes are no JPEG";
  contracts::ManualClock clock;
  auto source = open_images(dir.path(), clock);
  auto message = error_of([&] { source->next(); });
  EXPECT_NE(message.find("broken.jpg"), std::string::npos) << message;
}

TEST(VideoSource, ReadsEveryFrameThenEnds) {
  TempDir dir;
  const auto file = dir.path() / "clip.avi";
  {
    cv::VideoWriter writer(file.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10,
                           cv::Size(64, 48));
    if (!writer.isOpened()) GTEST_SKIP() << "this OpenCV cannot write MJPG .avi";
    for (int i = 0; i < 5; ++i) writer.write(solid(64, 48, {40, 80, 120}));
  }
  contracts::ManualClock clock;
  auto source = open_source("video:" + file.string(), clock);
  EXPECT_FALSE(source->live());
  EXPECT_EQ(source->describe(), "video:" + file.string());
  for (int i = 0; i < 5; ++i) {
    auto f = source->next();
    ASSERT_TRUE(f) << "frame " << i;
    EXPECT_EQ(f->frame_id, i);
    EXPECT_EQ(f->rgb.cols, 64);
    EXPECT_EQ(f->rgb.rows, 48);
    EXPECT_EQ(f->order, PixelOrder::kBgr);
    EXPECT_EQ(f->source, file.string());
  }
  EXPECT_EQ(source->next(), std::nullopt);
}

// The file as a camera: paced by the injected clock (the test moves it, so next() never
// sleeps), frames whose time has passed are skipped, the end loops to the start.
TEST(LiveVideoSource, PlaysAtTheFileRateSkipsWhenBehindAndLoops) {
  TempDir dir;
  const auto file = dir.path() / "clip.avi";
  {
    cv::VideoWriter writer(file.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10,
                           cv::Size(64, 48));
    if (!writer.isOpened()) GTEST_SKIP() << "this OpenCV cannot write MJPG .avi";
    for (int i = 0; i < 5; ++i) {
      const auto v = static_cast<unsigned char>(20 + 40 * i);
      writer.write(solid(64, 48, {v, v, v}));
    }
  }
  contracts::ManualClock clock;
  const std::string spec = "video:" + file.string() + "?live=1";
  auto source = open_source(spec, clock);
  EXPECT_TRUE(source->live());
  EXPECT_EQ(source->describe(), spec);
  // Which of the five frames was delivered: by its grey level.
  auto index_of = [](const Frame& f) {
    return static_cast<int>(std::lround((cv::mean(f.rgb)[0] - 20) / 40));
  };
  std::vector<int> seen;
  std::vector<std::int64_t> ids;
  auto take = [&] {
    auto f = source->next();
    ASSERT_TRUE(f);
    EXPECT_EQ(f->order, PixelOrder::kBgr);
    seen.push_back(index_of(*f));
    ids.push_back(f->frame_id);
  };
  take();                  // t = 0: frame 0
  clock.advance(100ms);    // frame 1 due
  take();
  clock.advance(305ms);    // 0.405 s: frames 2 and 3 passed while "busy", 4 is due
  take();
  clock.advance(100ms);    // 0.505 s: frame 5 = the first again (a 5-frame loop)
  take();
  clock.advance(100ms);
  take();
  EXPECT_EQ(seen, (std::vector<int>{0, 1, 4, 0, 1}));
  EXPECT_EQ(ids, (std::vector<std::int64_t>{0, 1, 2, 3, 4}));  // delivered frames, no gaps

  // fps= overrides the file's rate: 20 fps, so 50 ms is one frame.
  auto fast = open_source("video:" + file.string() + "?live=1&fps=20", clock);
  ASSERT_TRUE(fast->next());
  clock.advance(50ms);
  auto second = fast->next();
  ASSERT_TRUE(second);
  EXPECT_EQ(index_of(*second), 1);
}

TEST(LiveVideoSource, BadOptionsSayWhatIsAllowed) {
  TempDir dir;
  const auto file = dir.path() / "clip.avi";
  {
    cv::VideoWriter writer(file.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10,
                           cv::Size(64, 48));
    if (!writer.isOpened()) GTEST_SKIP() << "this OpenCV cannot write MJPG .avi";
    writer.write(solid(64, 48, {40, 80, 120}));
  }
  contracts::ManualClock clock;
  const auto base = "video:" + file.string();
  const auto unknown = error_of([&] { open_source(base + "?loop=1", clock); });
  EXPECT_NE(unknown.find("unknown option \"loop=1\""), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("live=1"), std::string::npos) << unknown;
  const auto fps = error_of([&] { open_source(base + "?live=1&fps=fast", clock); });
  EXPECT_NE(fps.find("fps=30"), std::string::npos) << fps;
  const auto no_live = error_of([&] { open_source(base + "?fps=30", clock); });
  EXPECT_NE(no_live.find("needs live=1"), std::string::npos) << no_live;
  const auto missing = error_of([&] { open_source("video:/nonexistent/x.mp4?live=1", clock); });
  EXPECT_NE(missing.find("no such file"), std::string::npos) << missing;
  // Without live=1 it is the plain offline file.
  EXPECT_FALSE(open_source(base + "?live=0", clock)->live());
}

TEST(VideoSource, MissingOrUndecodableFileIsAClearError) {
  TempDir dir;
  contracts::ManualClock clock;
  auto missing =
      error_of([&] { open_source("video:" + (dir.path() / "none.mp4").string(), clock); });
  EXPECT_NE(missing.find("video:"), std::string::npos) << missing;
  EXPECT_NE(missing.find("no such file"), std::string::npos) << missing;

  std::ofstream(dir.path() / "text.mp4") << "not a video at all";
  auto garbage =
      error_of([&] { open_source("video:" + (dir.path() / "text.mp4").string(), clock); });
  EXPECT_NE(garbage.find("text.mp4"), std::string::npos) << garbage;
  EXPECT_NE(garbage.find("cannot decode"), std::string::npos) << garbage;
}

TEST(OpenSource, BadSpecsSayWhatIsWrongAndWhatToUse) {
  contracts::ManualClock clock;
  const std::string help = "camera:N";
  for (const char* spec : {"webcam:0", "clip.mp4", "camera:", "camera:first", "camera:-1"}) {
    auto message = error_of([&] { open_source(spec, clock); });
    EXPECT_NE(message.find(std::string("'") + spec + "'"), std::string::npos) << message;
    EXPECT_NE(message.find("camera:"), std::string::npos) << message;
  }
}

TEST(OpenSource, ACameraThatIsNotThereNamesItself) {
  contracts::ManualClock clock;
  auto message = error_of([&] { open_source("camera:63", clock); });
  EXPECT_NE(message.find("camera:63"), std::string::npos) << message;
  EXPECT_NE(message.find("cannot open"), std::string::npos) << message;
}

TEST(GeneratorSource, NumbersAndStampsFramesAndEndsForGood) {
  contracts::ManualClock clock;
  int calls = 0;
  GeneratorSource source(
      [&](std::int64_t id) -> std::optional<cv::Mat> {
        ++calls;
        if (id == 2) return std::nullopt;
        return solid(4, 3, {1, 2, 3});
      },
      clock, "fixture:demo", /*live=*/false);
  EXPECT_EQ(source.describe(), "fixture:demo");
  clock.advance(5ms);
  auto a = source.next();
  clock.advance(5ms);
  auto b = source.next();
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->frame_id, 0);
  EXPECT_EQ(b->frame_id, 1);
  EXPECT_EQ(a->capture_time, 5ms);
  EXPECT_EQ(b->capture_time, 10ms);
  EXPECT_EQ(a->order, PixelOrder::kRgb);
  EXPECT_EQ(a->source, "fixture:demo");
  EXPECT_EQ(source.next(), std::nullopt);
  EXPECT_EQ(source.next(), std::nullopt);
  EXPECT_EQ(calls, 3);  // not asked again after the end
}

TEST(GeneratorSource, FailuresAndBadPixelsBecomeCaptureErrors) {
  contracts::ManualClock clock;
  GeneratorSource failing(
      [](std::int64_t) -> std::optional<cv::Mat> { throw std::runtime_error("lens cap on"); },
      clock, "fixture:x", true);
  auto message = error_of([&] { failing.next(); });
  EXPECT_NE(message.find("fixture:x"), std::string::npos) << message;
  EXPECT_NE(message.find("lens cap on"), std::string::npos) << message;

  GeneratorSource grey(
      [](std::int64_t) -> std::optional<cv::Mat> { return cv::Mat(4, 4, CV_8UC1); }, clock,
      "fixture:grey", false);
  EXPECT_NE(error_of([&] { grey.next(); }).find("CV_8UC3"), std::string::npos);
}

}  // namespace
}  // namespace gbdcs::vision
