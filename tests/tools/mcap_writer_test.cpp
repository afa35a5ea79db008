// McapWriter (tools/logplay/mcap_writer.h): the record layout of the MCAP
// spec, walked byte by byte here; the npm @mcap/core reader reads the files
// of a real session in tests/web/foxglove_test.sh.
#include "mcap_writer.h"

#include "robotalk/error.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace robotalk::logplay {
namespace {

std::uint64_t Le(const std::string& b, std::size_t at, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v |= std::uint64_t{static_cast<std::uint8_t>(b[at + i])} << (8 * i);
  return v;
}

std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// The opcodes of the records from `from` to the footer (inclusive).
std::vector<int> Walk(const std::string& b, std::size_t from) {
  std::vector<int> ops;
  std::size_t at = from;
  while (at + 9 <= b.size() - 8) {
    ops.push_back(static_cast<std::uint8_t>(b[at]));
    at += 9 + Le(b, at + 1, 8);
    if (ops.back() == 0x02) break;
  }
  EXPECT_EQ(at, b.size() - 8) << "records do not end at the trailing magic";
  return ops;
}

TEST(McapWriter, WritesChunksWithMessageIndexesAndAnIndexedSummary) {
  const std::string path =
      (std::filesystem::temp_directory_path() / "robotalk_mcap_writer_test.mcap").string();
  {
    McapWriter w(path, 200);  // small chunks: several of them
    const auto s = w.AddSchema("robotalk.Test", "jsonschema", R"({"type":"object"})");
    EXPECT_EQ(w.AddSchema("robotalk.Test", "jsonschema", R"({"type":"object"})"), s);
    const auto a = w.AddChannel(s, "/a", "json"), c = w.AddChannel(s, "/c", "json");
    EXPECT_EQ(w.AddChannel(s, "/a", "json"), a);
    for (int i = 0; i < 20; ++i)
      w.Write(i % 2 ? a : c, 1000 + i, 900 + i, R"({"i":)" + std::to_string(i) + "}");
    EXPECT_THROW(w.AddChannel(9, "/bad", "json"), Error);
    EXPECT_THROW(w.Write(77, 0, 0, "{}"), Error);
    w.Close();
    EXPECT_EQ(w.messages(), 20u);
  }
  const std::string b = ReadAll(path);
  const std::string magic("\x89MCAP0\r\n", 8);
  ASSERT_GT(b.size(), 16u);
  EXPECT_EQ(b.substr(0, 8), magic);
  EXPECT_EQ(b.substr(b.size() - 8), magic);
  const std::vector<int> ops = Walk(b, 8);
  ASSERT_GE(ops.size(), 4u);
  EXPECT_EQ(ops.front(), 0x01);  // Header
  EXPECT_EQ(ops.back(), 0x02);   // Footer
  int chunks = 0, data_end = 0, chunk_indexes = 0;
  for (std::size_t i = 0; i < ops.size(); ++i) {
    if (ops[i] == 0x06) {
      ++chunks;
      EXPECT_EQ(ops[i + 1], 0x07) << "a chunk is followed by its message indexes";
    }
    data_end += ops[i] == 0x0F;
    chunk_indexes += ops[i] == 0x08;
  }
  EXPECT_GT(chunks, 1);
  EXPECT_EQ(data_end, 1);
  EXPECT_EQ(chunk_indexes, chunks);
  // The footer: summary_start points at the first summary record (a Schema).
  const std::size_t footer = b.size() - 8 - 9 - 20;
  ASSERT_EQ(static_cast<std::uint8_t>(b[footer]), 0x02);
  const std::uint64_t summary_start = Le(b, footer + 9, 8), offsets_start = Le(b, footer + 17, 8);
  EXPECT_EQ(static_cast<std::uint8_t>(b[summary_start]), 0x03);
  EXPECT_EQ(static_cast<std::uint8_t>(b[offsets_start]), 0x0E);
  std::filesystem::remove(path);
}

TEST(McapWriter, ThrowsNamingAFileItCannotWrite) {
  try {
    McapWriter w("/no/such/dir/out.mcap");
    FAIL() << "no throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/no/such/dir/out.mcap"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace robotalk::logplay
