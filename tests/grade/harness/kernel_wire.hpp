// kernel_wire.hpp: the calls of the exercise kernels between two processes, for grading.
//
// A submission's code is hostile until graded. So it never runs in the process that judges it:
// the grading binary (grade-cases: the tests, the engine, and kernel_client.cpp in place of the
// kernels) runs the checks, and every call of an exercise kernel goes over a wire to a kernels
// process (grade-kernels-*: the engine, the kernels under test and kernel_server.cpp), which
// computes the answer and sends it back. Whatever the kernels' process prints, exits with or
// fakes, the verdict is written by a process it cannot reach.
//
// The wire is a pair of pipes of its own, descriptors 3 (calls in) and 4 (answers out) of the
// kernels' process (kWireIn, kWireOut), from its first instruction on: its standard output and
// error are the case's log, which the grader reads and bounds, so that a static object's
// constructor that prints before main reaches the log, never the wire. (Pipes rather than a
// socket: a call's round trip costs less.)
//
// A message is a header (kind, kernel, payload size) and a payload of plain values in the
// machine's byte order (both processes run on one machine):
//
//   client -> kernels   Call           a kernel's arguments, in order (an AccelerationField is
//                                      no bytes: it stays with the client, which runs it when
//                                      asked)
//   kernels -> client   Return         the result, then every argument passed by non-const
//                                      reference, as the kernel left it
//                       Throw          what the kernel threw
//                       Callback       the kernel calls its AccelerationField: its non-const
//                                      reference arguments as they are now (the caller sees them
//                                      change during the step, as it would in one process), then
//                                      the field's x, v and a
//   client -> kernels   CallbackReturn the field's a
//                       CallbackThrow  the field threw (the client keeps the exception, and
//                                      throws it again when the kernel lets it through)
//
// While it waits for a CallbackReturn, the kernels' process serves Calls (a field may run the
// engine, which calls kernels). The client trusts nothing it reads: every size is checked
// against the bytes there are, every matrix against the shape the call fixed (an argument the
// kernel may change comes back in the shape it had at the call; a callback's x, v and a have one
// column per particle of the call's state), before any of it is used; a message that does not
// parse, or a matrix of another shape, ends the kernels' process as a break of the protocol.
#pragma once

#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <span>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "clothlab/after_step/ground_collision.hpp"
#include "clothlab/after_step/plasticity.hpp"
#include "clothlab/after_step/self_collision.hpp"
#include "clothlab/after_step/spatial_hash.hpp"
#include "clothlab/after_step/strain_limiting.hpp"
#include "clothlab/after_step/tearing.hpp"
#include "clothlab/bodies/cloth.hpp"
#include "clothlab/core/game_loop.hpp"
#include "clothlab/core/types.hpp"
#include "clothlab/forces/aerodynamics.hpp"
#include "clothlab/forces/gravitation.hpp"
#include "clothlab/forces/gravity.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/euler.hpp"
#include "clothlab/integrators/local_global.hpp"
#include "clothlab/integrators/runge_kutta.hpp"
#include "clothlab/integrators/stability_limit.hpp"
#include "clothlab/integrators/vbd_vertex.hpp"
#include "clothlab/integrators/xpbd.hpp"

namespace clothlab::wire {

// Every kernel a student writes: the functions between BEGIN and END in exercises/. The grading
// binary defines each one as a call to the kernels' process; a kernel missing here leaves the
// grading binary with an undefined symbol, so the list cannot fall behind the engine's headers.
#define CLOTHLAB_EXERCISE_KERNELS(X)  \
  X(gravity_force)                    \
  X(gravitation_force)                \
  X(explicit_euler_step)              \
  X(symplectic_euler_step)            \
  X(spring_damper_force)              \
  X(spring_energy)                    \
  X(aerodynamic_force)                \
  X(fluid_drag_force)                 \
  X(bending_pairs)                    \
  X(collision_response)               \
  X(plastic_rest_length)              \
  X(select_tears)                     \
  X(midpoint_step)                    \
  X(rk4_step)                         \
  X(largest_stable_dt_explicit_euler) \
  X(strain_limit_correction)          \
  X(cell_of)                          \
  X(cell_hash)                        \
  X(pair_response)                    \
  X(accumulate)                       \
  X(xpbd_distance_projection)         \
  X(local_step_projection)            \
  X(vbd_vertex_block)                 \
  X(vbd_vertex_step)

#define CLOTHLAB_KERNEL_ENUM(name) name,
enum class Kernel : std::uint32_t { CLOTHLAB_EXERCISE_KERNELS(CLOTHLAB_KERNEL_ENUM) count };
#undef CLOTHLAB_KERNEL_ENUM

inline const char* kernel_name(std::uint32_t k) {
#define CLOTHLAB_KERNEL_NAME(name) #name,
  static constexpr const char* names[] = {CLOTHLAB_EXERCISE_KERNELS(CLOTHLAB_KERNEL_NAME)};
#undef CLOTHLAB_KERNEL_NAME
  return k < std::size(names) ? names[k] : "an unknown kernel";
}

enum class Kind : std::uint32_t {
  Call = 1,
  Return,
  Throw,
  Callback,
  CallbackReturn,
  CallbackThrow,
};

// What a kernel threw, in a Throw message.
enum class Thrown : std::uint32_t {
  NotImplemented = 1,  // a stub: exercise, lesson
  Exception,           // a std::exception: its what()
  Other,               // anything else
  Callback,            // the AccelerationField's own exception, let through
};

struct Header {
  std::uint32_t kind = 0;
  std::uint32_t kernel = 0;
  std::uint64_t size = 0;
};

// The kernels' ends of the wire: descriptor numbers, the same in every kernels' process.
constexpr int kWireIn = 3;   // calls come in here
constexpr int kWireOut = 4;  // answers go out here

// No message is larger: the largest state a grading case steps is a few thousand particles.
constexpr std::uint64_t kMaxMessage = std::uint64_t{256} << 20;

// A message that does not parse.
struct WireError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// --- Values to bytes and back -----------------------------------------------------------------

struct Writer {
  std::string bytes;
  void raw(const void* data, std::size_t size) {
    bytes.append(static_cast<const char*>(data), size);
  }
};

struct Reader {
  const char* at = nullptr;
  std::size_t left = 0;
  void raw(void* data, std::size_t size) {
    if (size > left) throw WireError("a message ends before its values do");
    std::memcpy(data, at, size);
    at += size;
    left -= size;
  }
  // A count of elements of `size` bytes each, which the message must still hold.
  std::size_t count(std::size_t size) {
    std::uint64_t n = 0;
    raw(&n, sizeof n);
    if (size != 0 && n > left / size) throw WireError("a message holds fewer values than it says");
    return static_cast<std::size_t>(n);
  }
  void expect_end() const {
    if (left != 0) throw WireError("a message holds more values than its kernel takes");
  }
};

template <class T>
concept Plain = std::is_arithmetic_v<T> || std::is_enum_v<T>;

// The fewest bytes a value of T takes in a message: what a count of them is checked against, so
// that a count cannot make the reader allocate more than the message's size over again.
template <class T>
constexpr std::size_t kMinBytes = 1;
template <Plain T>
constexpr std::size_t kMinBytes<T> = sizeof(T);
template <class A, class B>
constexpr std::size_t kMinBytes<std::pair<A, B>> = kMinBytes<A> + kMinBytes<B>;

template <Plain T>
void put(Writer& w, const T& value) {
  w.raw(&value, sizeof value);
}
template <Plain T>
void get(Reader& r, T& value) {
  r.raw(&value, sizeof value);
}

inline void put(Writer& w, const std::string& s) {
  put(w, std::uint64_t{s.size()});
  w.raw(s.data(), s.size());
}
inline void get(Reader& r, std::string& s) {
  s.resize(r.count(1));
  r.raw(s.data(), s.size());
}

inline void put(Writer& w, const Vec3& a) {
  w.raw(a.data(), sizeof(double) * 3);
}
inline void get(Reader& r, Vec3& a) {
  r.raw(a.data(), sizeof(double) * 3);
}

inline void put(Writer& w, const Matrix3X& m) {
  put(w, std::uint64_t(m.cols()));
  w.raw(m.data(), sizeof(double) * 3 * static_cast<std::size_t>(m.cols()));
}
inline void get(Reader& r, Matrix3X& m) {
  const std::size_t cols = r.count(3 * sizeof(double));
  m.resize(3, static_cast<Index>(cols));
  r.raw(m.data(), sizeof(double) * 3 * cols);
}

// A matrix that must have `cols` columns (the shape the call fixed): refused before it is read.
inline void get_shaped(Reader& r, Matrix3X& m, Index cols) {
  std::uint64_t n = 0;
  get(r, n);
  if (n != static_cast<std::uint64_t>(cols)) {
    throw WireError("a matrix of 3 x " + std::to_string(n) + " where the call's is 3 x " +
                    std::to_string(cols));
  }
  m.resize(3, cols);
  r.raw(m.data(), sizeof(double) * 3 * static_cast<std::size_t>(cols));
}

inline void put(Writer& w, const Mat3& a) {
  w.raw(a.data(), sizeof(double) * 9);
}
inline void get(Reader& r, Mat3& a) {
  r.raw(a.data(), sizeof(double) * 9);
}

template <class A, class B>
void put(Writer& w, const std::pair<A, B>& p) {
  put(w, p.first);
  put(w, p.second);
}
template <class A, class B>
void get(Reader& r, std::pair<A, B>& p) {
  get(r, p.first);
  get(r, p.second);
}

template <class T>
void put(Writer& w, const std::vector<T>& v) {
  put(w, std::uint64_t{v.size()});
  for (const T& x : v)
    put(w, x);
}
template <class T>
void get(Reader& r, std::vector<T>& v) {
  v.clear();
  v.resize(r.count(kMinBytes<T>));
  for (T& x : v)
    get(r, x);
}

// A span a kernel reads is sent as its elements; the kernels' process holds them in a vector
// (Stored below), which the kernel then sees as the span.
template <class T>
void put(Writer& w, std::span<const T> v) {
  put(w, std::uint64_t{v.size()});
  for (const T& x : v)
    put(w, x);
}

template <class T, std::size_t N>
void put(Writer& w, const std::array<T, N>& a) {
  for (const T& x : a)
    put(w, x);
}
template <class T, std::size_t N>
void get(Reader& r, std::array<T, N>& a) {
  for (T& x : a)
    get(r, x);
}

// The structs the kernels take and return, field by field. The static_asserts fail to compile
// when a field is added to one of them and not here.
#define CLOTHLAB_WIRE_STRUCT(Type, bytes, ...)                                       \
  static_assert(sizeof(Type) == (bytes), #Type " changed: list its fields here");    \
  inline void put(Writer& wire_out, const Type& wire_value) {                        \
    const auto& [__VA_ARGS__] = wire_value;                                          \
    std::apply([&](const auto&... wire_field) { (put(wire_out, wire_field), ...); }, \
               std::tie(__VA_ARGS__));                                               \
  }                                                                                  \
  inline void get(Reader& wire_in, Type& wire_value) {                               \
    auto& [__VA_ARGS__] = wire_value;                                                \
    std::apply([&](auto&... wire_field) { (get(wire_in, wire_field), ...); },        \
               std::tie(__VA_ARGS__));                                               \
  }

CLOTHLAB_WIRE_STRUCT(PointState, 6 * sizeof(double), r, v)
CLOTHLAB_WIRE_STRUCT(PlasticLimits, 3 * sizeof(double), yield_strain, flow_rate, max_strain)
CLOTHLAB_WIRE_STRUCT(StrainLimits, 2 * sizeof(double), max_strain, max_compression)
CLOTHLAB_WIRE_STRUCT(StrainCorrection, 6 * sizeof(double), dr1, dr2)
CLOTHLAB_WIRE_STRUCT(Cell, 3 * sizeof(std::int64_t), ix, iy, iz)
CLOTHLAB_WIRE_STRUCT(PairState, 12 * sizeof(double), r1, v1, r2, v2)
CLOTHLAB_WIRE_STRUCT(SelfContact, 4 * sizeof(double), thickness, e, mu_s, mu_d)
CLOTHLAB_WIRE_STRUCT(Substeps, sizeof(long) + 2 * sizeof(double), count, leftover, dropped)
CLOTHLAB_WIRE_STRUCT(RungeKuttaStages, 12 * sizeof(Matrix3X), x, v, a)
CLOTHLAB_WIRE_STRUCT(VertexSpring, 9 * sizeof(double), x_j, x_j_start, ks, kd, l0)
CLOTHLAB_WIRE_STRUCT(VertexBlock, 12 * sizeof(double), f, H)
#undef CLOTHLAB_WIRE_STRUCT
template <>
inline constexpr std::size_t kMinBytes<VertexSpring> = sizeof(VertexSpring);

// How the kernels' process holds an argument of type Param while the kernel runs: as the value
// itself, or, for a span (which owns nothing), in a vector of its elements.
template <class Param>
struct StoredAs {
  using type = std::decay_t<Param>;
};
template <class T>
struct StoredAs<std::span<const T>> {
  using type = std::vector<T>;
};
template <class Param>
using Stored = typename StoredAs<std::decay_t<Param>>::type;

// An AccelerationField is no bytes: it stays in the client's process.
inline void put(Writer&, const AccelerationField&) {}
inline void get(Reader&, AccelerationField&) {}

// Parameter I of a kernel is one it may change: passed by non-const reference.
template <class Param>
constexpr bool kIsOut =
    std::is_lvalue_reference_v<Param> && !std::is_const_v<std::remove_reference_t<Param>>;

// An argument the kernel may change comes back in the shape it had at the call: a kernel that
// resized one would have its caller read and write past the end of what it holds.
template <class T>
void get_kept(Reader& r, T& value) {
  get(r, value);
}
inline void get_kept(Reader& r, Matrix3X& m) {
  get_shaped(r, m, m.cols());
}
inline void get_kept(Reader& r, RungeKuttaStages& s) {
  for (std::array<Matrix3X, 4>* stage : {&s.x, &s.v, &s.a}) {
    for (Matrix3X& m : *stage)
      get_kept(r, m);
  }
}

// Writes (or reads) the kernel's changeable arguments, in order, from a tuple of its arguments.
template <class... Params, class Tuple>
void put_outs(Writer& w, const Tuple& values) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    ((kIsOut<Params> ? put(w, std::get<I>(values)) : void()), ...);
  }
  (std::index_sequence_for<Params...>{});
}
template <class... Params, class Tuple>
void get_outs(Reader& r, Tuple&& values) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (
        [&] {
          if constexpr (kIsOut<Params>) get_kept(r, std::get<I>(values));
        }(),
        ...);
  }
  (std::index_sequence_for<Params...>{});
}

// --- Messages over a file descriptor ---------------------------------------------------

struct Message {
  Header header;
  std::string payload;
  Reader reader() const { return Reader{payload.data(), payload.size()}; }
};

// Sends and receives whole messages over two file descriptors (a pipe each way). send() returns
// false when the other end is gone.
class Channel {
 public:
  Channel() = default;
  Channel(int in, int out) : in_(in), out_(out) {}

  bool send(Kind kind, Kernel kernel, const Writer& payload) const {
    return send(kind, static_cast<std::uint32_t>(kernel), payload);
  }
  bool send(Kind kind, std::uint32_t kernel, const Writer& payload) const {
    Header h{static_cast<std::uint32_t>(kind), kernel, payload.bytes.size()};
    std::string bytes(sizeof h, '\0');
    std::memcpy(bytes.data(), &h, sizeof h);
    bytes += payload.bytes;
    return write_all(bytes.data(), bytes.size());
  }

  // Fills m with the next message. Returns Received::End when the other end closed the pipe
  // between messages, Received::Broken when it stopped mid-message or sent a size beyond
  // kMaxMessage.
  enum class Received { Message, End, Broken };
  // Closes the descriptors (the other end then reads the end of the wire).
  void close() const {
    ::close(in_);
    if (out_ != in_) ::close(out_);
  }
  Received receive(Message& m) const {
    const Read header = read_all(&m.header, sizeof m.header);
    if (header != Read::All) return header == Read::Nothing ? Received::End : Received::Broken;
    if (m.header.size > kMaxMessage) return Received::Broken;
    m.payload.resize(static_cast<std::size_t>(m.header.size));
    return read_all(m.payload.data(), m.payload.size()) == Read::All || m.payload.empty()
               ? Received::Message
               : Received::Broken;
  }

 private:
  bool write_all(const char* data, std::size_t size) const {
    while (size > 0) {
      const ssize_t n = ::write(out_, data, size);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return false;
      data += n;
      size -= static_cast<std::size_t>(n);
    }
    return true;
  }
  enum class Read { All, Nothing, Part };
  Read read_all(void* to, std::size_t size) const {
    char* data = static_cast<char*>(to);
    const std::size_t wanted = size;
    while (size > 0) {
      const ssize_t n = ::read(in_, data, size);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return size == wanted ? Read::Nothing : Read::Part;
      data += n;
      size -= static_cast<std::size_t>(n);
    }
    return Read::All;
  }

  int in_ = -1;
  int out_ = -1;
};

}  // namespace clothlab::wire
