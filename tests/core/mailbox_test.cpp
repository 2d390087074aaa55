#include "animrt/core/mailbox.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

namespace animrt {
namespace {

struct Pair {
  double a = 0.0;
  double b = 0.0;  // always -a when written
  std::uint64_t n = 0;
};

TEST(Mailbox, GivesTheNewestValueOnceAndNothingUntilTheNext) {
  Mailbox<Pair> box;
  Pair out;
  EXPECT_FALSE(box.take(out));
  box.post(Pair{1.0, -1.0, 1});
  box.post(Pair{2.0, -2.0, 2});
  ASSERT_TRUE(box.take(out));
  EXPECT_EQ(out.n, 2u);
  EXPECT_EQ(out.a, 2.0);
  EXPECT_FALSE(box.take(out));
  box.post(Pair{3.0, -3.0, 3});
  ASSERT_TRUE(box.take(out));
  EXPECT_EQ(out.n, 3u);
}

TEST(Mailbox, AReaderNeverSeesAHalfWrittenValue) {
  Mailbox<Pair> box;
  std::atomic<bool> done{false};
  std::atomic<std::uint64_t> taken{0};
  std::uint64_t written = 0;
  // Writes until the reader has taken many values (or a generous cap). A
  // real writer posts now and then; one that never pauses may starve the
  // reader's bounded retries, which is allowed (it gets the next one).
  std::thread writer([&] {
    for (std::uint64_t i = 1; i <= 5'000'000 && (taken.load() < 2000 || i < 200000); ++i) {
      box.post(Pair{static_cast<double>(i), -static_cast<double>(i), i});
      written = i;
      if (i % 16 == 0) std::this_thread::yield();
    }
    done = true;
  });
  std::uint64_t last = 0;
  bool torn = false, backwards = false;
  while (!done.load()) {
    Pair p;
    if (!box.take(p)) continue;
    ++taken;
    if (p.b != -p.a || static_cast<double>(p.n) != p.a) torn = true;
    if (p.n <= last) backwards = true;
    last = p.n;
  }
  writer.join();
  Pair p;
  if (box.take(p)) last = p.n;
  EXPECT_FALSE(torn);
  EXPECT_FALSE(backwards);
  EXPECT_EQ(last, written);
  EXPECT_GE(taken.load(), 2000u);
}

}  // namespace
}  // namespace animrt
