// The bounded-input layer (replay/input_file.h): what every reader of a user-named file relies on.
#include "replay/input_file.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace sg {
namespace {
std::string scratch(const std::string& leaf) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("sg_input_file_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  return (dir / leaf).string();
}

void writeText(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

TEST(InputFile, ReadsARegularFileWhole) {
  const std::string p = scratch("ok.txt");
  writeText(p, "hello");
  std::string text, why;
  ASSERT_TRUE(readInputFile(p, 5, &text, &why)) << why;
  EXPECT_EQ(text, "hello");
}

TEST(InputFile, RefusesAFileOverTheLimitBeforeReadingIt) {
  const std::string p = scratch("big.txt");
  writeText(p, "123456");
  std::string text, why;
  EXPECT_FALSE(readInputFile(p, 5, &text, &why));
  EXPECT_EQ(why, "a file of at most 5 bytes, got 6");
  EXPECT_TRUE(text.empty());
}

TEST(InputFile, NamesAMissingFile) {
  std::string text, why;
  EXPECT_FALSE(readInputFile(scratch("missing.txt"), 5, &text, &why));
  EXPECT_EQ(why, "an existing file (not found)");
  EXPECT_FALSE(readInputFile("", 5, &text, &why));
  EXPECT_EQ(why, "a file name (got an empty one)");
}

TEST(InputFile, RefusesDirectoriesDevicesAndFifosWithoutBlocking) {
  std::string text, why;
  EXPECT_FALSE(readInputFile(std::filesystem::temp_directory_path().string(), 1 << 20, &text, &why));
  EXPECT_EQ(why, "a regular file, got a directory");
  EXPECT_FALSE(readInputFile("/dev/zero", 1 << 20, &text, &why));
  EXPECT_EQ(why, "a regular file, got a character device");
  const std::string fifo = scratch("fifo");
  ::unlink(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // No writer ever opens it: a blocking open would hang this test (ctest's timeout would fail it).
  EXPECT_FALSE(readInputFile(fifo, 1 << 20, &text, &why));
  EXPECT_EQ(why, "a regular file, got a FIFO");
  ::unlink(fifo.c_str());
}

TEST(InputFile, ReadAtPastTheEndIsAnErrorNotAShortRead) {
  const std::string p = scratch("short.bin");
  writeText(p, "abc");
  InputFile f;
  std::string why;
  ASSERT_TRUE(f.open(p, 100, &why)) << why;
  EXPECT_EQ(f.size(), 3u);
  uint8_t buf[4];
  EXPECT_FALSE(f.readAt(0, buf, &why));
  EXPECT_EQ(why, "1 more bytes at byte 3 (the file ends early or shrank while being read)");
  EXPECT_TRUE(f.readAt(1, std::span<uint8_t>(buf, 2), &why));
  EXPECT_EQ(buf[0], 'b');
}

TEST(InputFile, SameFileSeesThroughSpellingsAndHardLinks) {
  const std::string p = scratch("a.json");
  writeText(p, "{}");
  const std::filesystem::path dir = std::filesystem::path(p).parent_path();
  EXPECT_TRUE(sameFile(p, (dir / "." / "a.json").string()));
  const std::string link = scratch("b.json");
  ::unlink(link.c_str());
  ASSERT_EQ(::link(p.c_str(), link.c_str()), 0);
  EXPECT_TRUE(sameFile(p, link));
  writeText(scratch("c.json"), "{}");
  EXPECT_FALSE(sameFile(p, scratch("c.json")));
  EXPECT_FALSE(sameFile(p, scratch("nope.json")));
}
}  // namespace
}  // namespace sg
