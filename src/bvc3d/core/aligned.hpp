#pragma once
// Cache-line-aligned storage for the arrays of vector kernels: no AVX-512 load of an aligned block
// spans two cache lines (each such load costs two). Used as std::vector<T, CacheAligned<T>>.
#include <cstddef>
#include <new>

namespace bvc3d {

template <class T>
struct CacheAligned {
    using value_type = T;
    static constexpr std::align_val_t alignment{64};
    CacheAligned() = default;
    template <class U>
    CacheAligned(const CacheAligned<U>&) {}
    T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), alignment)); }
    void deallocate(T* p, std::size_t) { ::operator delete(p, alignment); }
    friend bool operator==(const CacheAligned&, const CacheAligned&) { return true; }
};

}  // namespace bvc3d
