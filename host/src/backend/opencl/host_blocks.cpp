#include "host_blocks.hpp"

#include <cstdlib>
#include <map>
#include <mutex>
#include <new>

namespace groovetrace::ocl {
namespace {

constexpr std::size_t kPage = 4096;
constexpr std::size_t kKeptMax = std::size_t{2} << 30;

struct Kept {
  std::mutex mutex;
  std::multimap<std::size_t, void*> blocks;  // capacity -> block
  std::size_t bytes = 0;
};

// Never destroyed: the driver calls buffer destructor callbacks (which give blocks back) on its
// own threads, and may do so while the process exits, after static destructors have run. A
// destroyed map there crashed test processes at exit now and then (SIGSEGV after PASSED).
Kept& kept() {
  static Kept* k = new Kept;
  return *k;
}

}  // namespace

void* take_host_block(std::size_t bytes, std::size_t* capacity) {
  const std::size_t want = (bytes + kPage - 1) / kPage * kPage;
  {
    Kept& k = kept();
    std::lock_guard<std::mutex> lock(k.mutex);
    // The smallest kept block that fits, unless it wastes more than an eighth.
    auto it = k.blocks.lower_bound(want);
    if (it != k.blocks.end() && it->first <= want + want / 8) {
      void* block = it->second;
      *capacity = it->first;
      k.bytes -= it->first;
      k.blocks.erase(it);
      return block;
    }
  }
  void* block = std::aligned_alloc(kPage, want);
  if (block == nullptr) throw std::bad_alloc();
  *capacity = want;
  return block;
}

void give_host_block(void* block, std::size_t capacity) {
  {
    Kept& k = kept();
    std::lock_guard<std::mutex> lock(k.mutex);
    if (k.bytes + capacity <= kKeptMax) {
      k.blocks.emplace(capacity, block);
      k.bytes += capacity;
      return;
    }
  }
  std::free(block);
}

}  // namespace groovetrace::ocl
