#include "base/process_heap.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace selfcal {
namespace {

// The heap keeps working as a heap after the preparation: blocks of every size, written and read back,
// freed and allocated again. (Whether the kernel grants huge pages is its choice: only the advice is ours.)
TEST(ProcessHeap, MallocKeepsWorkingAfterThePreparation) {
  const HeapPreparation prepared = PrepareProcessHeap(std::size_t{8} << 20);
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
  EXPECT_TRUE(prepared.malloc_options_set);  // a sanitizer's allocator takes no mallopt: it answers 0
#else
  (void)prepared;
#endif
  std::vector<void*> blocks;
  for (std::size_t size = 1; size <= (std::size_t{64} << 20); size *= 4) {
    char* block = static_cast<char*>(std::malloc(size));
    ASSERT_NE(block, nullptr) << size;
    std::memset(block, static_cast<int>(size % 251), size);
    EXPECT_EQ(block[size - 1], static_cast<char>(size % 251));
    blocks.push_back(block);
  }
  for (void* block : blocks) std::free(block);
  std::vector<double> again(std::size_t{1} << 22, 1.5);
  EXPECT_EQ(again.back(), 1.5);
}

// Where the kernel offers transparent huge pages on request ("always" or "madvise"), part of the heap is
// advised. (Where it does not, madvise may still succeed as a no-op, or fail without THP support: the
// heap works either way, which the test above checks.)
TEST(ProcessHeap, AdvisesHugePagesWhereTheKernelOffersThem) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's allocator does not take its memory from the program break";
#endif
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string mode;
  std::getline(in, mode);
  const HeapPreparation prepared = PrepareProcessHeap(std::size_t{8} << 20);
  if (mode.find("[always]") == std::string::npos && mode.find("[madvise]") == std::string::npos) {
    GTEST_SKIP() << "transparent huge pages not offered on request here: " << (mode.empty() ? "no THP" : mode);
  }
  EXPECT_GE(prepared.huge_page_bytes, std::size_t{2} << 20) << mode;
}

}  // namespace
}  // namespace selfcal
