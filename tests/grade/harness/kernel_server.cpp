// kernel_server.cpp: the main of a kernels process (grade-kernels-*), see kernel_wire.hpp.
//
// Linked with the engine and one set of kernels (the reference, the shipped stubs, or a
// submission's), it reads calls on the wire (descriptor kWireIn, which the grading binary gives
// it) and answers on kWireOut until the calls end. It holds no test and no expected value: it only
// computes. What the kernels print goes to the standard output and error, never onto the wire.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "clothlab/core/not_implemented.hpp"
#include "kernel_wire.hpp"

namespace {

using namespace clothlab;
using namespace clothlab::wire;

Channel g_channel;

[[noreturn]] void give_up(const char* why) {
  std::fprintf(stderr, "grade-kernels: %s\n", why);
  std::_Exit(3);
}

// Thrown out of a kernel by its AccelerationField when the client's field threw: the client
// throws its own exception again.
struct CallbackFailed {};

void serve(const Message& call);

// What a kernel's AccelerationField does here: asks the client to evaluate it, serving the calls
// the field makes meanwhile. `outs` writes the kernel's changeable arguments as they are now.
void call_back(const std::function<void(Writer&)>& outs, std::uint32_t kernel, const Matrix3X& x,
               const Matrix3X& v, Matrix3X& a) {
  Writer w;
  outs(w);
  put(w, x);
  put(w, v);
  put(w, a);
  if (!g_channel.send(Kind::Callback, kernel, w)) std::_Exit(0);
  for (;;) {
    Message m;
    if (g_channel.receive(m) != Channel::Received::Message) std::_Exit(0);  // the client is gone
    switch (static_cast<Kind>(m.header.kind)) {
      case Kind::CallbackReturn: {
        Reader r = m.reader();
        get(r, a);
        r.expect_end();
        return;
      }
      case Kind::CallbackThrow:
        throw CallbackFailed{};
      case Kind::Call:
        serve(m);
        break;
      default:
        give_up("the grader sent a message out of turn");
    }
  }
}

// One kernel: reads its arguments, calls it, sends the result and the changeable arguments.
template <class R, class... Params>
void answer(R (*kernel)(Params...), std::uint32_t id, Reader& in) {
  std::tuple<Stored<Params>...> values;
  std::apply([&](auto&... v) { (get(in, v), ...); }, values);
  in.expect_end();
  const std::function<void(Writer&)> outs = [&](Writer& w) { put_outs<Params...>(w, values); };
  std::apply(
      [&](auto&... v) {
        (
            [&](auto& value) {
              if constexpr (std::is_same_v<std::decay_t<decltype(value)>, AccelerationField>) {
                value = [&outs, id](const Matrix3X& xs, const Matrix3X& vs, Matrix3X& as) {
                  call_back(outs, id, xs, vs, as);
                };
              }
            }(v),
            ...);
      },
      values);
  Writer w;
  if constexpr (std::is_void_v<R>) {
    std::apply(kernel, values);
  } else {
    put(w, std::apply(kernel, values));
  }
  outs(w);
  if (!g_channel.send(Kind::Return, id, w)) std::_Exit(0);
}

using Answer = void (*)(std::uint32_t, Reader&);
#define CLOTHLAB_ANSWER(name) \
  [](std::uint32_t id, Reader& in) { answer(&::clothlab::name, id, in); },
constexpr Answer kAnswers[] = {CLOTHLAB_EXERCISE_KERNELS(CLOTHLAB_ANSWER)};
#undef CLOTHLAB_ANSWER
static_assert(std::size(kAnswers) == static_cast<std::size_t>(Kernel::count));

void send_thrown(std::uint32_t id, Thrown kind, const std::string& a, const std::string& b = "") {
  Writer w;
  put(w, kind);
  put(w, a);
  put(w, b);
  if (!g_channel.send(Kind::Throw, id, w)) std::_Exit(0);
}

void serve(const Message& call) {
  const std::uint32_t id = call.header.kernel;
  if (id >= std::size(kAnswers)) give_up("the grader called a kernel that does not exist");
  Reader in = call.reader();
  try {
    kAnswers[id](id, in);
  } catch (const WireError& e) {
    give_up(e.what());
  } catch (const CallbackFailed&) {
    send_thrown(id, Thrown::Callback, "");
  } catch (const NotImplemented& e) {
    send_thrown(id, Thrown::NotImplemented, e.exercise(), e.lesson());
  } catch (const std::exception& e) {
    send_thrown(id, Thrown::Exception, e.what());
  } catch (...) {
    send_thrown(id, Thrown::Other, "");
  }
}

}  // namespace

int main() {
  // The wire is a pair of pipes the grading binary made for it alone, there from the first
  // instruction (a static object's constructor runs before main, and may print what it likes:
  // that goes to the standard output, not here). Programs the kernels start do not get it.
  for (const int fd : {kWireIn, kWireOut}) {
    struct stat wire {};
    if (fstat(fd, &wire) != 0 || !S_ISFIFO(wire.st_mode)) {
      give_up(
          "no wire on descriptors 3 and 4: a grading binary starts this program, with the "
          "command in CLOTHLAB_KERNELS");
    }
    fcntl(fd, F_SETFD, FD_CLOEXEC);
  }
  g_channel = Channel(kWireIn, kWireOut);
  for (;;) {
    Message m;
    if (g_channel.receive(m) != Channel::Received::Message) return 0;  // the grader is done
    if (static_cast<Kind>(m.header.kind) != Kind::Call)
      give_up("the grader sent a message out of turn");
    serve(m);
    std::fflush(stdout);
  }
}
