// Structure-of-arrays storage for one part. Each field is a contiguous std::vector registered
// once with its name, unit and roles; output, checkpoints and re-sorting walk the registry,
// so a new field needs one `add_*` line and nothing else.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <deque>
#include <numeric>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "core/types.hpp"
#include "parallel/parallel.hpp"

namespace crater::fields {

/// What a field takes part in.
enum Role : unsigned {
  kNone = 0,
  kOutput = 1u << 0,   // written to VTU
  kRestart = 1u << 1,  // written to checkpoints
  kHalo = 1u << 2,     // copied to other ranks as ghosts (fields/exchange.hpp)
};
inline constexpr unsigned kStateRoles = kOutput | kRestart | kHalo;
/// For FieldSet::pack(): every field, whatever its roles (an entity that migrates to another
/// rank takes all of its data).
inline constexpr unsigned kEveryField = ~0u;

struct FieldInfo {
  std::string name;
  std::string unit;  // SI, e.g. "kg/m^3"; "1" for dimensionless
  unsigned roles = kNone;
};

/// Read-only view of one registered field, for writers.
struct FieldView {
  const FieldInfo* info;
  int components;  // 1 for scalars, D for vectors, 6 for tensors (SymTensor)
  bool is_integer;
  const Real* real_data;             // when !is_integer
  const std::int64_t* integer_data;  // when is_integer
  Index size;
};

/// The view named `name` among `views`, or nullptr. The pointer points into `views`, so a
/// temporary (`find_field(part.point_fields(), ...)`) does not compile: keep the vector.
inline const FieldView* find_field(const std::vector<FieldView>& views, std::string_view name) {
  for (const auto& v : views)
    if (v.info->name == name) return &v;
  return nullptr;
}
const FieldView* find_field(std::vector<FieldView>&& views, std::string_view name) = delete;

template <int D>
class FieldSet {
 public:
  using Column = std::variant<std::vector<Real>, std::vector<Vec<D>>, std::vector<std::int64_t>,
                              std::vector<SymTensor>>;

  Index size() const { return size_; }
  /// Counts the changes of which entity sits where (resize, permute, compact, load, unpack):
  /// a part that keeps indices into its fields across steps (e.g. the entities its last
  /// contact forces touched) knows them stale when this moved.
  std::uint64_t layout_epoch() const { return layout_epoch_; }

  std::vector<Real>& add_scalar(std::string name, std::string unit, unsigned roles) {
    return std::get<std::vector<Real>>(add(std::move(name), std::move(unit), roles,
                                           std::vector<Real>(static_cast<std::size_t>(size_))));
  }
  std::vector<Vec<D>>& add_vector(std::string name, std::string unit, unsigned roles) {
    return std::get<std::vector<Vec<D>>>(
        add(std::move(name), std::move(unit), roles,
            std::vector<Vec<D>>(static_cast<std::size_t>(size_), Vec<D>::Zero())));
  }
  /// A symmetric tensor per entity (core/types.hpp: six components, VTK's order, in 2D too).
  std::vector<SymTensor>& add_tensor(std::string name, std::string unit, unsigned roles) {
    return std::get<std::vector<SymTensor>>(
        add(std::move(name), std::move(unit), roles,
            std::vector<SymTensor>(static_cast<std::size_t>(size_), SymTensor::Zero())));
  }
  std::vector<std::int64_t>& add_integer(std::string name, std::string unit, unsigned roles) {
    return std::get<std::vector<std::int64_t>>(
        add(std::move(name), std::move(unit), roles,
            std::vector<std::int64_t>(static_cast<std::size_t>(size_))));
  }

  /// Resizes every field; new entries are zero.
  void resize(Index n) {
    ++layout_epoch_;
    for (auto& c : columns_)
      std::visit(
          [n](auto& v) {
            using T = typename std::decay_t<decltype(v)>::value_type;
            v.resize(static_cast<std::size_t>(n), zero<T>());
          },
          c.data);
    size_ = n;
  }

  /// Reorders every field: new[i] = old[order[i]]. Used to sort entities by cell.
  void permute(std::span<const Index> order) {
    if (static_cast<Index>(order.size()) != size_)
      throw std::logic_error("FieldSet::permute: order has the wrong size");
    ++layout_epoch_;
    for (auto& c : columns_)
      std::visit(
          [&](auto& v) {
            const auto copy = v;
            parallel::for_each(static_cast<Index>(order.size()), [&](Index i) {
              v[static_cast<std::size_t>(i)] =
                  copy[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
            });
          },
          c.data);
  }

  /// Drops the entities whose `keep` entry is 0; the others keep their relative order (entity
  /// i moves to the number of kept entities before it), so the result is the same for any
  /// thread count. Used to remove particles that left the domain. Returns the new size.
  Index compact(std::span<const std::uint8_t> keep) {
    if (static_cast<Index>(keep.size()) != size_)
      throw std::logic_error("FieldSet::compact: keep mask has the wrong size");
    ++layout_epoch_;
    for (auto& c : columns_)
      std::visit(
          [&](auto& v) {
            std::size_t k = 0;
            for (std::size_t i = 0; i < keep.size(); ++i)
              if (keep[i]) {
                if (k != i) v[k] = std::move(v[i]);
                ++k;
              }
            v.resize(k);
          },
          c.data);
    size_ = static_cast<Index>(std::count_if(keep.begin(), keep.end(), [](auto k) { return k; }));
    return size_;
  }

  /// Every field, raw (checkpoints: io/checkpoint StateWriter / StateReader). All fields are
  /// written, rates included: the next half kick uses the forces of the saved state.
  template <class Writer>
  void save(Writer& w) const {
    w.tag("fields");
    w.value(static_cast<std::uint64_t>(columns_.size()));
    for (const auto& c : columns_) {
      w.tag(c.info.name);
      std::visit([&](const auto& v) { w.vector(v); }, c.data);
    }
  }
  template <class Reader>
  void load(Reader& r) {
    r.tag("fields");
    ++layout_epoch_;
    if (r.template value<std::uint64_t>() != columns_.size())
      r.fail("it holds another set of fields");
    bool first = true;
    for (auto& c : columns_) {
      r.tag(c.info.name);
      std::visit([&](auto& v) { r.vector(v); }, c.data);
      const auto n = static_cast<Index>(std::visit([](const auto& v) { return v.size(); }, c.data));
      if (!first && n != size_) r.fail("its fields have different lengths");
      size_ = n;
      first = false;
    }
  }

  /// Bytes one entity takes in pack() for `roles`.
  std::size_t packed_bytes(unsigned roles) const {
    std::size_t n = 0;
    for (const auto& c : columns_)
      if (takes(c.info.roles, roles))
        n += std::visit(
            [](const auto& v) {
              return entry_bytes<typename std::decay_t<decltype(v)>::value_type>();
            },
            c.data);
    return n;
  }

  /// Appends to `out` the entries of the entities `which` (in that order) of the fields having
  /// any of `roles` (kEveryField: all), field after field in registration order: what an
  /// exchange between ranks sends (fields/exchange.hpp).
  void pack(std::span<const Index> which, unsigned roles, std::vector<std::byte>& out) const {
    std::size_t at = out.size();
    out.resize(at + which.size() * packed_bytes(roles));
    for (const auto& c : columns_) {
      if (!takes(c.info.roles, roles)) continue;
      std::visit(
          [&](const auto& v) {
            using T = typename std::decay_t<decltype(v)>::value_type;
            for (Index i : which) {
              std::memcpy(out.data() + at, entry_data(v[static_cast<std::size_t>(i)]),
                          entry_bytes<T>());
              at += entry_bytes<T>();
            }
          },
          c.data);
    }
  }

  /// Appends the entities that pack() with the same `roles` wrote to `in`, on a set with the
  /// same fields; the fields without those roles get zeros. Returns the number appended.
  Index unpack_append(std::span<const std::byte> in, unsigned roles) {
    const std::size_t per = packed_bytes(roles);
    if (per == 0 ? !in.empty() : in.size() % per != 0)
      throw std::logic_error("FieldSet::unpack_append: the bytes are not whole entities");
    const Index n = per == 0 ? 0 : static_cast<Index>(in.size() / per);
    std::vector<Index> which(static_cast<std::size_t>(n));
    std::iota(which.begin(), which.end(), size_);
    resize(size_ + n);
    unpack_into(which, in, roles);
    return n;
  }

  /// Overwrites the entities `which` (in that order) with what pack() of as many entities with
  /// the same `roles` wrote to `in`: the ghosts' fields refreshed from their owners.
  void unpack_into(std::span<const Index> which, std::span<const std::byte> in, unsigned roles) {
    if (in.size() != which.size() * packed_bytes(roles))
      throw std::logic_error("FieldSet::unpack_into: the bytes do not match the entities");
    ++layout_epoch_;
    std::size_t at = 0;
    for (auto& c : columns_) {
      if (!takes(c.info.roles, roles)) continue;
      std::visit(
          [&](auto& v) {
            using T = typename std::decay_t<decltype(v)>::value_type;
            for (const Index i : which) {
              std::memcpy(entry_data(v[static_cast<std::size_t>(i)]), in.data() + at,
                          entry_bytes<T>());
              at += entry_bytes<T>();
            }
          },
          c.data);
    }
  }

  /// Views of the fields having any of `roles`, in registration order.
  std::vector<FieldView> views(unsigned roles) const {
    std::vector<FieldView> out;
    for (const auto& c : columns_) {
      if ((c.info.roles & roles) == 0) continue;
      FieldView fv{&c.info, 1, false, nullptr, nullptr, size_};
      if (auto* r = std::get_if<std::vector<Real>>(&c.data)) {
        fv.real_data = r->data();
      } else if (auto* v = std::get_if<std::vector<Vec<D>>>(&c.data)) {
        fv.components = D;
        fv.real_data = v->empty() ? nullptr : v->front().data();
      } else if (auto* t = std::get_if<std::vector<SymTensor>>(&c.data)) {
        fv.components = static_cast<int>(SymTensor::RowsAtCompileTime);
        fv.real_data = t->empty() ? nullptr : t->front().data();
      } else {
        fv.is_integer = true;
        fv.integer_data = std::get<std::vector<std::int64_t>>(c.data).data();
      }
      out.push_back(fv);
    }
    return out;
  }

 private:
  struct Entry {
    FieldInfo info;
    Column data;
  };

  static bool takes(unsigned field_roles, unsigned roles) {
    return roles == kEveryField || (field_roles & roles) != 0;
  }
  // An entry's bytes: a number, or an Eigen vector's or tensor's coefficients.
  template <class T>
  static constexpr std::size_t entry_bytes() {
    if constexpr (std::is_arithmetic_v<T>)
      return sizeof(T);
    else
      return sizeof(typename T::Scalar) * static_cast<std::size_t>(T::SizeAtCompileTime);
  }
  template <class T>
  static auto* entry_data(T& e) {
    if constexpr (std::is_arithmetic_v<std::remove_const_t<T>>)
      return &e;
    else
      return e.data();
  }

  template <class T>
  static T zero() {
    if constexpr (std::is_same_v<T, Vec<D>> || std::is_same_v<T, SymTensor>)
      return T::Zero();
    else
      return T{};
  }

  Column& add(std::string name, std::string unit, unsigned roles, Column data) {
    for (const auto& c : columns_)
      if (c.info.name == name) throw std::logic_error("FieldSet: duplicate field " + name);
    columns_.push_back(Entry{FieldInfo{std::move(name), std::move(unit), roles}, std::move(data)});
    return columns_.back().data;
  }

  std::deque<Entry> columns_;  // deque: references handed out stay valid as fields are added
  Index size_ = 0;
  std::uint64_t layout_epoch_ = 0;
};

}  // namespace crater::fields
