// grade-confine: the last step before a submission's kernels program runs (sandbox.hpp).
//
//   grade-confine HOME PROGRAM [ARGS...]
//
// runs PROGRAM with an environment of three variables (PATH, LANG=C, HOME) and under a seccomp
// filter that lets it start threads but no other process, and take memory only as its address
// space (bounded by RLIMIT_AS, which it inherits): no System V shared memory, no memory files, no
// new namespaces. So a case is one process, and its memory is bounded as a whole: its address
// space, and the small memory-backed folders the sandbox gives it. A filter is inherited by every
// thread and survives exec, and nothing the kernels do can lift it.
#include <linux/audit.h>
#include <linux/filter.h>
#include <linux/seccomp.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <string>

namespace {

#if defined(__x86_64__)
constexpr unsigned kArch = AUDIT_ARCH_X86_64;
#elif defined(__aarch64__)
constexpr unsigned kArch = AUDIT_ARCH_AARCH64;
#else
#error "grade-confine knows the system calls of x86-64 and AArch64 only"
#endif

// Threads count against RLIMIT_NPROC too: this many leaves room for any pool a course sees, while
// the address space bounds their stacks (8 MiB each by default) long before.
constexpr rlim_t kMaxThreads = 1024;

constexpr sock_filter statement(unsigned short code, unsigned k) {
  return sock_filter{code, 0, 0, k};
}
constexpr sock_filter jump(unsigned short code, unsigned k, unsigned char yes, unsigned char no) {
  return sock_filter{code, yes, no, k};
}
constexpr unsigned kDeny = SECCOMP_RET_ERRNO | EPERM;
// clone3 passes its flags in memory the filter cannot read: the C library then falls back to
// clone, whose flags it can.
constexpr unsigned kNoSuchCall = SECCOMP_RET_ERRNO | ENOSYS;

// Denies system call `nr` with `ret`: two instructions.
#define CLOTHLAB_DENY(nr, ret) \
  jump(BPF_JMP | BPF_JEQ | BPF_K, (nr), 0, 1), statement(BPF_RET | BPF_K, (ret))

bool load_filter() {
  constexpr unsigned kArgLow = offsetof(seccomp_data, args[0]);  // little-endian: the low word
  sock_filter filter[] = {
    // Another architecture's calls (x86-64's i386 entry) have other numbers: refused whole.
    statement(BPF_LD | BPF_W | BPF_ABS, offsetof(seccomp_data, arch)),
    jump(BPF_JMP | BPF_JEQ | BPF_K, kArch, 1, 0),
    statement(BPF_RET | BPF_K, SECCOMP_RET_KILL_PROCESS),
    statement(BPF_LD | BPF_W | BPF_ABS, offsetof(seccomp_data, nr)),
#if defined(__x86_64__)
    // x32's calls are x86-64's numbers with bit 30 set.
    jump(BPF_JMP | BPF_JGE | BPF_K, 0x40000000U, 0, 1),
    statement(BPF_RET | BPF_K, kDeny),
    CLOTHLAB_DENY(SYS_fork, kDeny),
    CLOTHLAB_DENY(SYS_vfork, kDeny),
#endif
    CLOTHLAB_DENY(SYS_clone3, kNoSuchCall),
    CLOTHLAB_DENY(SYS_shmget, kDeny),
    CLOTHLAB_DENY(SYS_memfd_create, kDeny),
    CLOTHLAB_DENY(SYS_io_uring_setup, kDeny),
    CLOTHLAB_DENY(SYS_unshare, kDeny),
    CLOTHLAB_DENY(SYS_setns, kDeny),
    // clone makes a thread when its flags hold CLONE_THREAD, a process otherwise.
    jump(BPF_JMP | BPF_JEQ | BPF_K, SYS_clone, 1, 0),
    statement(BPF_RET | BPF_K, SECCOMP_RET_ALLOW),
    statement(BPF_LD | BPF_W | BPF_ABS, kArgLow),
    jump(BPF_JMP | BPF_JSET | BPF_K, CLONE_THREAD, 0, 1),
    statement(BPF_RET | BPF_K, SECCOMP_RET_ALLOW),
    statement(BPF_RET | BPF_K, kDeny),
  };
  const sock_fprog program{static_cast<unsigned short>(sizeof filter / sizeof filter[0]), filter};
  return prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) == 0 &&
         prctl(PR_SET_SECCOMP, SECCOMP_MODE_FILTER, &program) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fputs("usage: grade-confine HOME PROGRAM [ARGS...]\n", stderr);
    return 2;
  }
  const rlimit threads{kMaxThreads, kMaxThreads};
  setrlimit(RLIMIT_NPROC, &threads);
  if (!load_filter()) {
    std::perror("grade-confine: cannot load the seccomp filter that keeps a case to one process");
    return 126;
  }
  std::string home = std::string("HOME=") + argv[1];
  char path[] = "PATH=/usr/bin:/bin";
  char lang[] = "LANG=C";
  char* env[] = {path, lang, home.data(), nullptr};
  execve(argv[2], argv + 2, env);
  std::perror("grade-confine: cannot execute the kernels program");
  return 127;
}
