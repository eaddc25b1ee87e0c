// An allocator whose blocks start on a cache line (64 bytes), for the arrays the hot loops stream through.
// An array that starts mid-line (malloc aligns to 16 bytes) makes every row of a grid whose width is a whole
// number of lines start mid-line too, and every 512-bit load of a row split two lines; where the heap puts
// the arrays would then set the speed (docs/PERFORMANCE.md).
#pragma once

#include <cstddef>
#include <new>
#include <vector>

namespace clothsim {

inline constexpr std::size_t kCacheLine = 64;

template <class T>
struct CacheAlignedAllocator {
    using value_type = T;
    CacheAlignedAllocator() = default;
    template <class U>
    constexpr CacheAlignedAllocator(const CacheAlignedAllocator<U>&) noexcept {}
    T* allocate(std::size_t n) {
        return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(kCacheLine)));
    }
    void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, std::align_val_t(kCacheLine)); }
    template <class U>
    bool operator==(const CacheAlignedAllocator<U>&) const noexcept { return true; }
};

// A std::vector whose data() is 64-byte aligned.
template <class T>
using AlignedVector = std::vector<T, CacheAlignedAllocator<T>>;

}  // namespace clothsim
