// OutputLines (robotalk-client/cli/output_lines.h): the CLI's reply lines
// written by a thread of their own, so that a stdout that takes nothing never
// holds the thread that sends a sequence's frames.
#include "output_lines.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <string>

namespace robotalk::cli {
namespace {

std::string ReadAll(int fd) {
  std::string text;
  char buffer[4096];
  for (ssize_t n; (n = read(fd, buffer, sizeof buffer)) > 0;)
    text.append(buffer, static_cast<std::size_t>(n));
  return text;
}

TEST(OutputLines, WritesEveryLineInOrderAndFinishWaitsForThem) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  {
    OutputLines out(fds[1]);
    for (int i = 0; i < 100; ++i) out.Add("line " + std::to_string(i) + "\n");
    EXPECT_EQ(out.Finish(), 0u);
    EXPECT_TRUE(out.idle());
  }
  close(fds[1]);
  std::string want;
  for (int i = 0; i < 100; ++i) want += "line " + std::to_string(i) + "\n";
  EXPECT_EQ(ReadAll(fds[0]), want);
  close(fds[0]);
}

TEST(OutputLines, AddNeverWaitsForADescriptorThatTakesNothingAndCountsWhatItDrops) {
  // A full pipe nobody reads: Add returns at once; past kMaxQueuedBytes the
  // texts are dropped and counted; once the reader drains, the rest is
  // written and Finish says how many were dropped.
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  fcntl(fds[0], F_SETFL, fcntl(fds[0], F_GETFL) | O_NONBLOCK);
  const std::string chunk(4096, 'x');
  fcntl(fds[1], F_SETFL, fcntl(fds[1], F_GETFL) | O_NONBLOCK);
  std::size_t filler = 0;
  for (ssize_t n; (n = write(fds[1], chunk.data(), chunk.size())) > 0;) filler += static_cast<std::size_t>(n);
  fcntl(fds[1], F_SETFL, fcntl(fds[1], F_GETFL) & ~O_NONBLOCK);  // the writer thread blocks in it
  OutputLines out(fds[1]);
  const std::string line(1023, 'y');
  const auto began = std::chrono::steady_clock::now();
  constexpr int kLines = 5 * 1024;  // 5 MiB: 1 MiB past the bound
  for (int i = 0; i < kLines; ++i) out.Add(line + "\n");
  EXPECT_LT(std::chrono::steady_clock::now() - began, std::chrono::seconds(2))
      << "Add waited for the descriptor";
  EXPECT_FALSE(out.idle());
  std::size_t read_bytes = 0;
  char buffer[65536];
  while (!out.idle() || read_bytes == 0) {  // the reader comes back
    const ssize_t n = read(fds[0], buffer, sizeof buffer);
    if (n > 0) read_bytes += static_cast<std::size_t>(n);
  }
  const std::uint64_t dropped = out.Finish();
  for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) read_bytes += static_cast<std::size_t>(n);
  EXPECT_GT(dropped, 0u);
  EXPECT_EQ(read_bytes, filler + (kLines - dropped) * 1024) << "the filler, then every line kept";
  close(fds[0]);
  close(fds[1]);
}

TEST(OutputLines, ADescriptorWhoseReaderIsGoneLosesItsLinesNeverTheProcess) {
  // EPIPE, never SIGPIPE (the writer thread blocks every signal).
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  close(fds[0]);
  OutputLines out(fds[1]);
  out.Add("a\n");
  out.Add("b\n");
  const std::uint64_t lost = out.Finish();
  EXPECT_GE(lost, 1u);
  out.Add("c\n");  // after the failure: counted at once
  EXPECT_EQ(out.Finish(), lost + 1);
  close(fds[1]);
}

}  // namespace
}  // namespace robotalk::cli
