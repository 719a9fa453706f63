// The viewer's scene clock (app/scene_player.h), without a window.
#include "app/scene_player.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <thread>

#include "scratch_dir.h"

namespace sylva::app {
namespace {

const std::string kFireworks = std::string(SYLVA_SOURCE_DIR) + "/examples/scenes/fireworks.xml";

std::unique_ptr<ScenePlayer> Player(const std::string& path = kFireworks) {
  SceneLoad load = LoadSceneForView(path, {}, false, 1);
  EXPECT_TRUE(load.scene) << load.diagnostics;
  if (!load.scene) return nullptr;
  auto p = ScenePlayer::Create(std::move(load.scene));
  EXPECT_TRUE(bool(p));
  return p ? std::move(*p) : nullptr;
}

// Every sprite position of a frame, in order.
std::vector<draw::Vec3f> SpritePositions(const ScenePlayer& p) {
  std::vector<draw::Vec3f> all;
  for (const draw::Sprites& s : p.Frame().sprites)
    all.insert(all.end(), s.positions.begin(), s.positions.end());
  return all;
}

TEST(ScenePlayer, StepAdvancesOneFrameAndPauses) {
  auto p = Player();
  ASSERT_TRUE(p);
  p->Play();
  ASSERT_TRUE(p->Step().ok());
  EXPECT_FALSE(p->playing());
  EXPECT_NEAR(p->time(), 1.0 / 30, 1e-9) << "fireworks.xml runs at 30 fps";
  ASSERT_TRUE(p->Step().ok());
  EXPECT_NEAR(p->time(), 2.0 / 30, 1e-9);
}

TEST(ScenePlayer, PlayingAdvancesAtMostOneFramePerDrawnFrame) {
  auto p = Player();
  ASSERT_TRUE(p);
  p->Play();
  // A whole second passed since the last drawn frame: still one frame.
  ASSERT_TRUE(p->Update(1.0, 0.03).ok());
  EXPECT_NEAR(p->time(), 1.0 / 30, 1e-9);
  EXPECT_TRUE(p->slower()) << "a second behind is slower than real time";
  // Drawn frames at 60 Hz: one simulation frame every other drawn frame.
  auto q = Player();
  q->Play();
  for (int i = 0; i < 60; ++i) ASSERT_TRUE(q->Update(1.0 / 60, 0.03).ok());
  EXPECT_NEAR(q->time(), 1.0, 1.5 / 30) << "60 drawn frames at 60 Hz";
  EXPECT_FALSE(q->slower()) << "at t = " << q->time();
}

TEST(ScenePlayer, PausedDoesNotAdvance) {
  auto p = Player();
  ASSERT_TRUE(p);
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(p->Update(0.1, 0.03).ok());
  EXPECT_EQ(p->time(), 0.0);
}

TEST(ScenePlayer, SeekForwardWithinABudgetTakesSeveralDrawnFrames) {
  auto p = Player();
  ASSERT_TRUE(p);
  p->Seek(1.0);
  // A budget too small for two frames: one frame per call.
  ASSERT_TRUE(p->Update(0, 1e-12).ok());
  EXPECT_NEAR(p->time(), 1.0 / 30, 1e-9);
  EXPECT_TRUE(p->seeking());
  ASSERT_TRUE(p->Update(0, 0).ok());  // no budget: all the way
  EXPECT_NEAR(p->time(), 1.0, 1e-9);
  EXPECT_FALSE(p->seeking());
}

TEST(ScenePlayer, SeekBackwardResetsAndMatchesAFreshRun) {
  auto p = Player();
  ASSERT_TRUE(p);
  p->Seek(3.0);
  ASSERT_TRUE(p->Update(0, 0).ok());
  p->Seek(2.0);
  ASSERT_TRUE(p->Update(0, 0).ok());
  EXPECT_NEAR(p->time(), 2.0, 1e-9);
  auto fresh = Player();
  fresh->Seek(2.0);
  ASSERT_TRUE(fresh->Update(0, 0).ok());
  ASSERT_GT(fresh->particles(), 0u) << "fireworks at t = 2 has shells in the air";
  EXPECT_EQ(p->particles(), fresh->particles());
  EXPECT_EQ(SpritePositions(*p), SpritePositions(*fresh)) << "the same state after seeking back";
}

TEST(ScenePlayer, ResetGoesBackToZero) {
  auto p = Player();
  ASSERT_TRUE(p);
  p->Seek(2.0);
  ASSERT_TRUE(p->Update(0, 0).ok());
  const size_t before = p->particles();
  ASSERT_GT(before, 0u);
  p->Reset();
  // The new Simulation is made in the background; the old state is drawn
  // until an Update swaps it in.
  EXPECT_TRUE(p->rebuilding());
  EXPECT_EQ(p->particles(), before);
  EXPECT_NEAR(p->time(), 2.0, 1e-9);
  ASSERT_TRUE(p->Update(0, 0).ok());  // no budget: waits for it
  EXPECT_FALSE(p->rebuilding());
  EXPECT_EQ(p->time(), 0.0);
  EXPECT_EQ(p->particles(), 0u);
}

TEST(ScenePlayer, SeekingBackWithABudgetNeverWaitsForTheRebuild) {
  auto p = Player();
  ASSERT_TRUE(p);
  p->Seek(2.0);
  ASSERT_TRUE(p->Update(0, 0).ok());
  p->Seek(1.0);
  // Drawn frames with a budget go on while the rebuild runs, then the seek
  // continues from t = 0 and arrives.
  for (int i = 0; i < 10000 && p->seeking(); ++i) {
    ASSERT_TRUE(p->Update(0, 0.03).ok());
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_FALSE(p->seeking());
  EXPECT_NEAR(p->time(), 1.0, 1e-9);
}

TEST(ScenePlayer, PlayingStopsAtTheEndAndRestartsFromZero) {
  auto p = Player();
  ASSERT_TRUE(p);
  p->Seek(p->duration());
  ASSERT_TRUE(p->Update(0, 0).ok());
  p->Play();
  EXPECT_TRUE(p->seeking()) << "play at the end starts again from t = 0";
  ASSERT_TRUE(p->Update(0, 0).ok());
  EXPECT_EQ(p->time(), 0.0);
  p->Seek(p->duration() - 1.0 / 30);
  ASSERT_TRUE(p->Update(0, 0).ok());
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(p->Update(1.0 / 30, 0.03).ok());
  EXPECT_FALSE(p->playing()) << "t = " << p->time() << " of " << p->duration();
  EXPECT_NEAR(p->time(), p->duration(), 1e-9);
}

TEST(ScenePlayer, TrianglesOfTheFrameAreTheBuiltScenes) {
  auto p = Player();
  ASSERT_TRUE(p);
  EXPECT_EQ(TrianglesOf(p->Frame()), p->loaded().built.trianglesDrawn);
}

TEST(LoadSceneForView, WatchesTheSceneAndItsGrammars) {
  SceneLoad load = LoadSceneForView(kFireworks, {}, false, 1);
  ASSERT_TRUE(load.scene) << load.diagnostics;
  ASSERT_EQ(load.watched.size(), 2u);
  EXPECT_NE(load.watched[0].find("fireworks.xml"), std::string::npos) << load.watched[0];
  EXPECT_NE(load.watched[1].find("fig2_07a_sympodial.lsys"), std::string::npos) << load.watched[1];
}

TEST(LoadSceneForView, AnErrorIsABadInputWithItsLocation) {
  const auto dir = testing::ScratchDir("sylva_scene_player_");
  const std::string path = (dir / "bad.xml").string();
  std::ofstream(path) << "<scene version=\"1\">\n  <sky topp=\"#000000\"/>\n</scene>\n";
  SceneLoad load = LoadSceneForView(path, {}, false, 1);
  EXPECT_FALSE(load.scene);
  EXPECT_EQ(load.exit, 2);
  EXPECT_NE(load.diagnostics.find("bad.xml:2:8: error"), std::string::npos) << load.diagnostics;
  ASSERT_EQ(load.watched.size(), 1u);
  EXPECT_EQ(load.watched[0], path);
}

}  // namespace
}  // namespace sylva::app
