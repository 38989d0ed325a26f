// kernel_client.cpp: the exercise kernels of a grading binary, each a call to the kernels'
// process (see kernel_wire.hpp).
//
// The kernels' process is started at the first call, from the command in CLOTHLAB_KERNELS (the
// path of a grade-kernels-* program, or `clothlab grade`'s sandbox around one: its arguments
// separated by the character 0x1f), and lives until the grading binary ends. When it dies
// during a call, the call throws KernelsEnded, whose text starts with "crashed: signal N" for a
// signal (app/grade/kernels_crash.hpp); the grader reads that as the case crashing, as if the
// kernel had run in this process.
#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "app/grade/kernels_crash.hpp"
#include "clothlab/core/not_implemented.hpp"
#include "kernel_wire.hpp"

namespace clothlab {

namespace {

using namespace wire;

// The kernels' process ended (or broke the protocol) during a call.
struct KernelsEnded : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Kernels {
 public:
  // The channel to the kernels' process, started at the first call; throws KernelsEnded when it
  // is gone.
  const Channel& channel() {
    if (pid_ == 0) start();
    if (!gone_.empty()) throw KernelsEnded(gone_);
    return channel_;
  }

  // Called when a send or receive failed during a call of `kernel`, or when the kernels' process
  // broke the protocol (`broke` says how): waits for the process, and throws what became of it.
  [[noreturn]] void ended(std::uint32_t kernel, const char* broke = nullptr) {
    if (gone_.empty()) {
      const std::string during = std::string(" during a call of ") + kernel_name(kernel);
      // Its pipes closed: it is ending, or it closed them itself and lives on; it gets two
      // seconds to end before it is stopped.
      channel_.close();
      int status = 0;
      pid_t done = 0;
      for (int waited_ms = 0; broke == nullptr && waited_ms < 2000; waited_ms += 5) {
        done = waitpid(pid_, &status, WNOHANG);
        if (done != 0) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      if (done != pid_) {
        kill(pid_, SIGKILL);
        while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
        }
        if (broke == nullptr) broke = "it closed its pipes and went on running";
      }
      // In the sandbox, the kernels' process is bubblewrap's child, and bubblewrap exits with
      // 128 + N when its child dies of signal N (as a shell does): read that as the signal.
      const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 0;
      const int signal = WIFSIGNALED(status)             ? WTERMSIG(status)
                         : code > 128 && code < 128 + 65 ? code - 128
                                                         : 0;
      if (broke != nullptr) {
        gone_ =
            std::string("the exercise's code broke the kernels' protocol (") + broke + ")" + during;
      } else if (code == 127) {
        gone_ = "the kernels program (CLOTHLAB_KERNELS) could not be started" + during;
      } else if (signal != 0) {
        gone_ = std::string(app::grading::kKernelsCrashed) + std::to_string(signal) +
                " (in the exercise's code, which runs in a process of its own," + during + ")";
      } else {
        gone_ = "the exercise's code ended its process with exit status " + std::to_string(code) +
                during + ": a call to exit()?";
      }
    }
    throw KernelsEnded(gone_);
  }

  // Calls are made one at a time. The thread in a call may call again from inside an
  // AccelerationField (nested calls); another thread waits its turn.
  std::recursive_mutex lock;
  // The AccelerationField's exception, kept to be thrown again when the kernel lets it through.
  std::exception_ptr field_error;

 private:
  void start() {
    const char* command = std::getenv("CLOTHLAB_KERNELS");
    if (command == nullptr || *command == '\0') {
      throw std::runtime_error(
          "CLOTHLAB_KERNELS is not set: a grading binary runs the exercise kernels in a "
          "process of their own; set it to the kernels program to use, e.g. "
          "CLOTHLAB_KERNELS=build/grade-kernels-reference (`clothlab grade` does this)");
    }
    std::vector<std::string> args;
    std::string arg;
    for (const char* c = command;; ++c) {
      if (*c == '\x1f' || *c == '\0') {
        args.push_back(arg);
        arg.clear();
        if (*c == '\0') break;
      } else {
        arg += *c;
      }
    }
    std::vector<char*> argv;
    for (std::string& a : args)
      argv.push_back(a.data());
    argv.push_back(nullptr);

    // A process of the same user may not read or write this one's memory or descriptors. (Not
    // under AddressSanitizer, whose leak check at exit must trace this process's threads.)
#ifndef __SANITIZE_ADDRESS__
    prctl(PR_SET_DUMPABLE, 0);
#endif
    signal(SIGPIPE, SIG_IGN);  // a write to a dead kernels' process fails instead of killing us
    int calls[2], answers[2];
    if (pipe2(calls, O_CLOEXEC) != 0 || pipe2(answers, O_CLOEXEC) != 0)
      throw std::runtime_error("cannot make the kernels' pipes");
    const pid_t pid = fork();
    if (pid < 0) throw std::runtime_error("cannot start the kernels' process");
    if (pid == 0) {
      // The two pipes go as descriptors kWireIn and kWireOut, and nothing else of this process:
      // every other descriptor (the grader's events among them) is closed. The standard input
      // reads nothing; the standard output joins the standard error, the case's log. (Each pipe
      // is first moved above both numbers, so that neither dup2 lands on the other's pipe.)
      const int in = fcntl(calls[0], F_DUPFD, kWireOut + 1);
      const int out = fcntl(answers[1], F_DUPFD, kWireOut + 1);
      dup2(in, kWireIn);
      dup2(out, kWireOut);
      const int null_fd = open("/dev/null", O_RDONLY);
      if (null_fd > 0) dup2(null_fd, STDIN_FILENO);
      dup2(STDERR_FILENO, STDOUT_FILENO);
      close_range(kWireOut + 1, ~0U, 0);
      signal(SIGPIPE, SIG_DFL);
      execv(argv[0], argv.data());
      const char message[] = "cannot execute the kernels' program (CLOTHLAB_KERNELS)\n";
      [[maybe_unused]] auto ignored = write(STDERR_FILENO, message, sizeof message - 1);
      _exit(127);
    }
    close(calls[0]);
    close(answers[1]);
    pid_ = pid;
    channel_ = Channel(answers[0], calls[1]);
  }

  pid_t pid_ = 0;
  Channel channel_;
  std::string gone_;  // why the kernels' process is no more, once it is not
};

Kernels& kernels() {
  static Kernels k;
  return k;
}

// Throws again, in this process, what the kernel threw in its own.
[[noreturn]] void rethrow(Kernels& k, std::uint32_t id, Reader& r) {
  Thrown kind{};
  std::string a, b;
  get(r, kind);
  get(r, a);
  get(r, b);
  r.expect_end();
  switch (kind) {
    case Thrown::NotImplemented:
      throw NotImplemented(a, b);
    case Thrown::Exception:
      throw std::runtime_error(a);
    case Thrown::Callback:
      if (k.field_error) std::rethrow_exception(std::exchange(k.field_error, nullptr));
      throw std::runtime_error("the acceleration field failed");
    case Thrown::Other:
      throw std::runtime_error(std::string("the exercise's code threw something that is not a "
                                           "std::exception, in ") +
                               kernel_name(id));
  }
  k.ended(id, "an unknown kind of exception");
}

// One call of a kernel: sends the arguments, runs the AccelerationField when asked, and returns
// the result with the changeable arguments updated.
template <class R, class... Params>
R call(Kernel kernel, R (*)(Params...), std::type_identity_t<Params>... args) {
  Kernels& k = kernels();
  const std::lock_guard hold(k.lock);
  const auto id = static_cast<std::uint32_t>(kernel);
  const Channel& channel = k.channel();
  const AccelerationField* field = nullptr;
  Index particles = -1;  // the columns of the call's state (its first matrix), which a field gets
  (
      [&](const auto& value) {
        using Value = std::decay_t<decltype(value)>;
        if constexpr (std::is_same_v<Value, AccelerationField>) field = &value;
        if constexpr (std::is_same_v<Value, Matrix3X>) {
          if (particles < 0) particles = value.cols();
        }
      }(args),
      ...);
  Writer w;
  (put(w, args), ...);
  if (!channel.send(Kind::Call, kernel, w)) k.ended(id);
  auto values = std::forward_as_tuple(args...);
  const char* in = "";  // the message being read, for a break of the protocol
  for (;;) {
    Message m;
    const Channel::Received got = channel.receive(m);
    if (got == Channel::Received::End) k.ended(id);
    if (got == Channel::Received::Broken) k.ended(id, "a message cut short, or too large");
    if (m.header.kernel != id) k.ended(id, "an answer for another kernel");
    Reader r = m.reader();
    try {
      switch (static_cast<Kind>(m.header.kind)) {
        case Kind::Return: {
          in = " in its answer";
          if constexpr (std::is_void_v<R>) {
            get_outs<Params...>(r, values);
            r.expect_end();
            return;
          } else {
            R result{};
            get(r, result);
            get_outs<Params...>(r, values);
            r.expect_end();
            return result;
          }
        }
        case Kind::Throw:
          in = " in what it threw";
          rethrow(k, id, r);
        case Kind::Callback: {
          if (field == nullptr) k.ended(id, "a callback from a kernel that takes none");
          in = " in a call of its AccelerationField";
          get_outs<Params...>(r, values);
          // The field (the test's, or the world's) reads and writes one column per particle.
          Matrix3X x, v, a;
          get_shaped(r, x, particles);
          get_shaped(r, v, particles);
          get_shaped(r, a, particles);
          r.expect_end();
          Writer reply;
          try {
            (*field)(x, v, a);
            put(reply, a);
          } catch (...) {
            k.field_error = std::current_exception();
            if (!channel.send(Kind::CallbackThrow, kernel, reply)) k.ended(id);
            break;
          }
          if (!channel.send(Kind::CallbackReturn, kernel, reply)) k.ended(id);
          break;
        }
        default:
          k.ended(id, "a message out of turn");
      }
    } catch (const WireError& e) {
      k.ended(id, (e.what() + std::string(in)).c_str());
    }
  }
}

// A kernel's result that indexes what its caller holds (a test, or the engine) must index inside
// it, or the caller would read and write past the end: one out of range fails the case, as an
// exception from the kernel would, naming the kernel and the value.
void check_index(const char* kernel, const char* what, std::int64_t index, std::int64_t size) {
  if (index >= 0 && index < size) return;
  throw std::out_of_range(std::string(kernel) + " returned " + what + " " + std::to_string(index) +
                          ", out of range: it must be at least 0 and less than " +
                          std::to_string(size));
}

}  // namespace

#define CLOTHLAB_KERNEL(name) wire::Kernel::name, &name

Vec3 gravity_force(double m, const Vec3& g) {
  return call(CLOTHLAB_KERNEL(gravity_force), m, g);
}

Vec3 gravitation_force(const Vec3& r1, double m1, const Vec3& r2, double m2, double G) {
  return call(CLOTHLAB_KERNEL(gravitation_force), r1, m1, r2, m2, G);
}

PointState explicit_euler_step(const Vec3& r, const Vec3& v, const Vec3& f, double inv_m,
                               double dt) {
  return call(CLOTHLAB_KERNEL(explicit_euler_step), r, v, f, inv_m, dt);
}

PointState symplectic_euler_step(const Vec3& r, const Vec3& v, const Vec3& f, double inv_m,
                                 double dt) {
  return call(CLOTHLAB_KERNEL(symplectic_euler_step), r, v, f, inv_m, dt);
}

Vec3 spring_damper_force(const Vec3& r1, const Vec3& r2, const Vec3& v1, const Vec3& v2, double ks,
                         double kd, double l0) {
  return call(CLOTHLAB_KERNEL(spring_damper_force), r1, r2, v1, v2, ks, kd, l0);
}

double spring_energy(const Vec3& r1, const Vec3& r2, double ks, double l0) {
  return call(CLOTHLAB_KERNEL(spring_energy), r1, r2, ks, l0);
}

Vec3 aerodynamic_force(const Vec3& r1, const Vec3& r2, const Vec3& r3, const Vec3& v1,
                       const Vec3& v2, const Vec3& v3, const Vec3& v_air, double rho, double cd) {
  return call(CLOTHLAB_KERNEL(aerodynamic_force), r1, r2, r3, v1, v2, v3, v_air, rho, cd);
}

Vec3 fluid_drag_force(const Vec3& v, const Vec3& v_air, double rho, double cd, double a) {
  return call(CLOTHLAB_KERNEL(fluid_drag_force), v, v_air, rho, cd, a);
}

std::vector<IndexPair> bending_pairs(Index rows, Index cols) {
  std::vector<IndexPair> pairs = call(CLOTHLAB_KERNEL(bending_pairs), rows, cols);
  for (const IndexPair& p : pairs) {
    for (const Index i : {p.first, p.second})
      check_index("bending_pairs", "the particle index", i, rows * cols);
  }
  return pairs;
}

PointState collision_response(const Vec3& r, const Vec3& v, const Vec3& n, double depth, double e,
                              double mu_s, double mu_d) {
  return call(CLOTHLAB_KERNEL(collision_response), r, v, n, depth, e, mu_s, mu_d);
}

double plastic_rest_length(double l, double l0, double l_built, const PlasticLimits& limits,
                           double dt) {
  return call(CLOTHLAB_KERNEL(plastic_rest_length), l, l0, l_built, limits, dt);
}

std::vector<size_t> select_tears(const std::vector<double>& strain,
                                 const std::vector<std::pair<Index, Index>>& ends,
                                 double tear_strain, size_t max_tears) {
  std::vector<size_t> torn =
      call(CLOTHLAB_KERNEL(select_tears), strain, ends, tear_strain, max_tears);
  const auto springs = static_cast<std::int64_t>(std::min(strain.size(), ends.size()));
  for (const size_t k : torn)
    check_index("select_tears", "the spring index", static_cast<std::int64_t>(k), springs);
  return torn;
}

void midpoint_step(Matrix3X& x, Matrix3X& v, double dt, const AccelerationField& accel,
                   RungeKuttaStages& stages) {
  call(CLOTHLAB_KERNEL(midpoint_step), x, v, dt, accel, stages);
}

void rk4_step(Matrix3X& x, Matrix3X& v, double dt, const AccelerationField& accel,
              RungeKuttaStages& stages) {
  call(CLOTHLAB_KERNEL(rk4_step), x, v, dt, accel, stages);
}

double largest_stable_dt_explicit_euler(double k, double m, double c) {
  return call(CLOTHLAB_KERNEL(largest_stable_dt_explicit_euler), k, m, c);
}

StrainCorrection strain_limit_correction(const Vec3& r1, const Vec3& r2, double w1, double w2,
                                         double l0, const StrainLimits& limits) {
  return call(CLOTHLAB_KERNEL(strain_limit_correction), r1, r2, w1, w2, l0, limits);
}

Cell cell_of(const Vec3& x, double h) {
  return call(CLOTHLAB_KERNEL(cell_of), x, h);
}

std::size_t cell_hash(const Cell& c, std::size_t table_size) {
  const std::size_t slot = call(CLOTHLAB_KERNEL(cell_hash), c, table_size);
  if (slot >= table_size) {
    throw std::out_of_range("cell_hash returned the slot " + std::to_string(slot) +
                            ", out of range: it must be less than table_size, " +
                            std::to_string(table_size));
  }
  return slot;
}

PairState pair_response(const PairState& in, double w1, double w2, const SelfContact& contact) {
  return call(CLOTHLAB_KERNEL(pair_response), in, w1, w2, contact);
}

Substeps accumulate(double leftover, double frame_time, double dt, long max_substeps) {
  return call(CLOTHLAB_KERNEL(accumulate), leftover, frame_time, dt, max_substeps);
}

double xpbd_distance_projection(Vec3& x_i, Vec3& x_j, double w_i, double w_j, double l0,
                                double alpha_tilde, double lambda) {
  return call(CLOTHLAB_KERNEL(xpbd_distance_projection), x_i, x_j, w_i, w_j, l0, alpha_tilde,
              lambda);
}

Vec3 local_step_projection(const Vec3& x_i, const Vec3& x_j, double l0, const Vec3& d_previous) {
  return call(CLOTHLAB_KERNEL(local_step_projection), x_i, x_j, l0, d_previous);
}

VertexBlock vbd_vertex_block(const Vec3& x_i, const Vec3& x_i_start, const Vec3& y_i, double w_i,
                             double h, std::span<const VertexSpring> springs) {
  return call(CLOTHLAB_KERNEL(vbd_vertex_block), x_i, x_i_start, y_i, w_i, h, springs);
}

Vec3 vbd_vertex_step(const Vec3& x_i, const Vec3& x_i_start, const Vec3& y_i, double w_i, double h,
                     std::span<const VertexSpring> springs) {
  return call(CLOTHLAB_KERNEL(vbd_vertex_step), x_i, x_i_start, y_i, w_i, h, springs);
}

}  // namespace clothlab
