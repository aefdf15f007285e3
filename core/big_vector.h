#pragma once
// BigVector: the container of a mesh's large flat arrays (nodes, cells, faces). It behaves like
// std::vector for trivially relocatable elements, but a large block is an anonymous mapping that
// grows with mremap: growing a gigabyte array moves page mappings instead of copying the data
// into freshly faulted pages. Large blocks are also marked for transparent huge pages, which
// cuts page faults sharply (docs/results/solver-choices.md). Both matter: filling memory is
// the mesher's main cost.
#include <sys/mman.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <iterator>
#include <new>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace naris {

template <class T>
class BigVector {
 public:
  using value_type = T;
  using size_type = std::size_t;
  using iterator = T*;
  using const_iterator = const T*;
  using reference = T&;
  using const_reference = const T&;

  BigVector() = default;
  explicit BigVector(size_type n) { resize(n); }
  BigVector(size_type n, const T& value) { assign(n, value); }
  BigVector(std::initializer_list<T> values) { assign(values.begin(), values.end()); }
  template <class It, class = typename std::iterator_traits<It>::iterator_category>
  BigVector(It first, It last) {
    assign(first, last);
  }
  BigVector(const BigVector& o) { assign(o.begin(), o.end()); }
  BigVector(BigVector&& o) noexcept
      : data_(std::exchange(o.data_, nullptr)),
        size_(std::exchange(o.size_, 0)),
        capacity_(std::exchange(o.capacity_, 0)),
        mapped_(std::exchange(o.mapped_, false)) {}
  BigVector& operator=(const BigVector& o) {
    if (this != &o) assign(o.begin(), o.end());
    return *this;
  }
  BigVector& operator=(BigVector&& o) noexcept {
    if (this != &o) {
      release();
      data_ = std::exchange(o.data_, nullptr);
      size_ = std::exchange(o.size_, 0);
      capacity_ = std::exchange(o.capacity_, 0);
      mapped_ = std::exchange(o.mapped_, false);
    }
    return *this;
  }
  ~BigVector() { release(); }

  T* data() { return data_; }
  const T* data() const { return data_; }
  size_type size() const { return size_; }
  size_type capacity() const { return capacity_; }
  bool empty() const { return size_ == 0; }
  T* begin() { return data_; }
  T* end() { return data_ + size_; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }
  T& operator[](size_type i) { return data_[i]; }
  const T& operator[](size_type i) const { return data_[i]; }
  T& front() { return data_[0]; }
  T& back() { return data_[size_ - 1]; }
  const T& back() const { return data_[size_ - 1]; }

  void reserve(size_type n) {
    if (n <= capacity_) return;
    const std::size_t bytes = n * sizeof(T);
    // Elements are relocated bytewise: true of the plain arrays and fixed-size Eigen vectors
    // stored here, though Eigen's types do not advertise trivial copyability.
    void* p;
    if (mapped_) {
      p = mremap(static_cast<void*>(data_), capacity_ * sizeof(T), bytes, MREMAP_MAYMOVE);
      if (p == MAP_FAILED) throw std::bad_alloc();
    } else if (bytes >= kMapThreshold) {
      p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      if (p == MAP_FAILED) throw std::bad_alloc();
      if (size_) std::memcpy(p, static_cast<void*>(data_), size_ * sizeof(T));
      std::free(static_cast<void*>(data_));
      mapped_ = true;
    } else {
      p = std::realloc(static_cast<void*>(data_), bytes);
      if (!p) throw std::bad_alloc();
    }
    data_ = static_cast<T*>(p);
    capacity_ = n;
    if (mapped_) advise_huge_pages();
  }
  void push_back(const T& v) {
    if (size_ == capacity_) grow();
    new (data_ + size_++) T(v);
  }
  template <class... Args>
  T& emplace_back(Args&&... args) {
    if (size_ == capacity_) grow();
    return *new (data_ + size_++) T(std::forward<Args>(args)...);
  }
  void pop_back() { --size_; }
  void clear() { size_ = 0; }
  void resize(size_type n) {
    reserve(n);
    for (size_type i = size_; i < n; ++i) new (data_ + i) T{};
    size_ = n;
  }
  void resize(size_type n, const T& value) {
    reserve(n);
    for (size_type i = size_; i < n; ++i) new (data_ + i) T(value);
    size_ = n;
  }
  void assign(size_type n, const T& value) {
    clear();
    resize(n, value);
  }
  template <class It>
  void assign(It first, It last) {
    clear();
    reserve(static_cast<size_type>(std::distance(first, last)));
    for (; first != last; ++first) new (data_ + size_++) T(*first);
  }
  T* erase(T* first, T* last) {
    std::memmove(static_cast<void*>(first), last,
                 static_cast<std::size_t>(end() - last) * sizeof(T));
    size_ -= static_cast<size_type>(last - first);
    return first;
  }
  friend bool operator==(const BigVector& a, const BigVector& b) {
    return a.size_ == b.size_ && std::equal(a.begin(), a.end(), b.begin());
  }

 private:
  static_assert(std::is_trivially_destructible_v<T>, "BigVector holds plain data only");
  static constexpr std::size_t kMapThreshold = std::size_t{1} << 20;

  // Growth by 2×: with mremap a growth costs page-table updates, not copies, so a generous
  // factor only reserves address space; untouched pages cost nothing.
  void grow() { reserve(std::max<size_type>(16, 2 * capacity_)); }
  void advise_huge_pages() {
    madvise(static_cast<void*>(data_), capacity_ * sizeof(T), MADV_HUGEPAGE);
  }
  void release() {
    if (mapped_)
      munmap(static_cast<void*>(data_), capacity_ * sizeof(T));
    else
      std::free(static_cast<void*>(data_));
    data_ = nullptr;
    size_ = capacity_ = 0;
    mapped_ = false;
  }

  T* data_ = nullptr;
  size_type size_ = 0;
  size_type capacity_ = 0;
  bool mapped_ = false;
};

}  // namespace naris
