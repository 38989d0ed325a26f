// grade-confine: the last step before a submission's kernels program runs (sandbox.hpp).
//
//   grade-confine [--no-writes] HOME PROGRAM [ARGS...]
//
// runs PROGRAM with an environment of three variables (PATH, LANG=C, HOME) and under a seccomp
// filter that lets it start threads but no other process, and take memory only as its address
// space (bounded by RLIMIT_AS, which it inherits): no System V shared memory, no memory files, no
// new namespaces; and it may not trace or reach into another process's memory. So a case is one
// process, and its memory is bounded as a whole: its address space, and the small memory-backed
// folders the sandbox gives it. With --no-writes (where there is no sandbox), it may also create,
// change or remove no file and open no socket: the machine's own /tmp is no place to hold gigabytes
// in, nor the grader's folders a place to plant links. A filter is inherited by every thread and
// survives exec, and nothing the kernels do can lift it.
#include <fcntl.h>
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
#include <cstdlib>
#include <string>
#include <vector>

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

// The calls that make, change or remove a file, a folder or a link, and sockets: refused with
// --no-writes. (open and openat are refused only when their flags ask to write or create.)
constexpr long kWriteCalls[] = {
#if defined(__x86_64__)
    SYS_creat,     SYS_mkdir,    SYS_rmdir,     SYS_unlink,    SYS_rename,
    SYS_link,      SYS_symlink,  SYS_truncate,  SYS_mknod,     SYS_chmod,
    SYS_chown,     SYS_lchown,   SYS_renameat,
#endif
    SYS_mkdirat,   SYS_unlinkat, SYS_renameat2, SYS_linkat,    SYS_symlinkat,
    SYS_mknodat,   SYS_fchmodat, SYS_fchownat,  SYS_utimensat, SYS_setxattr,
    SYS_lsetxattr, SYS_socket,   SYS_socketpair};
// And what only root may do, were the kernels root (--sandbox off --kernels-as-root).
constexpr long kRootCalls[] = {SYS_mount,       SYS_umount2,      SYS_pivot_root,    SYS_chroot,
                               SYS_init_module, SYS_finit_module, SYS_delete_module, SYS_reboot,
                               SYS_swapon,      SYS_swapoff,      SYS_kexec_load};

bool load_filter(bool no_writes) {
  constexpr unsigned kArgLow = offsetof(seccomp_data, args[0]);  // little-endian: the low word
  std::vector<sock_filter> filter = {
    // Another architecture's calls (x86-64's i386 entry) have other numbers: refused whole.
    statement(BPF_LD | BPF_W | BPF_ABS, offsetof(seccomp_data, arch)),
    jump(BPF_JMP | BPF_JEQ | BPF_K, kArch, 1, 0),
    statement(BPF_RET | BPF_K, SECCOMP_RET_KILL_PROCESS),
    statement(BPF_LD | BPF_W | BPF_ABS, offsetof(seccomp_data, nr)),
#if defined(__x86_64__)
    // x32's calls are x86-64's numbers with bit 30 set.
    jump(BPF_JMP | BPF_JGE | BPF_K, 0x40000000U, 0, 1),
    statement(BPF_RET | BPF_K, kDeny),
#endif
  };
  const auto deny = [&](long nr, unsigned ret) {
    filter.push_back(jump(BPF_JMP | BPF_JEQ | BPF_K, static_cast<unsigned>(nr), 0, 1));
    filter.push_back(statement(BPF_RET | BPF_K, ret));
  };
  // A call whose argument `arg` has any of `bits` set is refused.
  const auto deny_flags = [&](long nr, int arg, unsigned bits) {
    filter.push_back(jump(BPF_JMP | BPF_JEQ | BPF_K, static_cast<unsigned>(nr), 0, 4));
    filter.push_back(statement(BPF_LD | BPF_W | BPF_ABS,
                               static_cast<unsigned>(offsetof(seccomp_data, args[0]) + 8 * arg)));
    filter.push_back(jump(BPF_JMP | BPF_JSET | BPF_K, bits, 0, 1));
    filter.push_back(statement(BPF_RET | BPF_K, kDeny));
    filter.push_back(statement(BPF_RET | BPF_K, SECCOMP_RET_ALLOW));
  };
#if defined(__x86_64__)
  deny(SYS_fork, kDeny);
  deny(SYS_vfork, kDeny);
#endif
  deny(SYS_clone3, kNoSuchCall);
  // Nor may they reach into another process (the grading binary, another case) by its memory.
  for (const long nr : {SYS_shmget, SYS_memfd_create, SYS_io_uring_setup, SYS_unshare, SYS_setns,
                        SYS_ptrace, SYS_process_vm_readv, SYS_process_vm_writev})
    deny(nr, kDeny);
  if (no_writes) {
    for (const long nr : kWriteCalls)
      deny(nr, kDeny);
    for (const long nr : kRootCalls)
      deny(nr, kDeny);
    deny(SYS_openat2, kNoSuchCall);  // its flags are in memory: the C library falls back to openat
    constexpr unsigned kWriting = O_WRONLY | O_RDWR | O_CREAT | O_TRUNC;
#if defined(__x86_64__)
    deny_flags(SYS_open, 1, kWriting);
#endif
    deny_flags(SYS_openat, 2, kWriting);
  }
  // clone makes a thread when its flags hold CLONE_THREAD, a process otherwise.
  filter.push_back(jump(BPF_JMP | BPF_JEQ | BPF_K, SYS_clone, 1, 0));
  filter.push_back(statement(BPF_RET | BPF_K, SECCOMP_RET_ALLOW));
  filter.push_back(statement(BPF_LD | BPF_W | BPF_ABS, kArgLow));
  filter.push_back(jump(BPF_JMP | BPF_JSET | BPF_K, CLONE_THREAD, 0, 1));
  filter.push_back(statement(BPF_RET | BPF_K, SECCOMP_RET_ALLOW));
  filter.push_back(statement(BPF_RET | BPF_K, kDeny));
  const sock_fprog program{static_cast<unsigned short>(filter.size()), filter.data()};
  return prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) == 0 &&
         prctl(PR_SET_SECCOMP, SECCOMP_MODE_FILTER, &program) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  const bool no_writes = argc > 1 && std::string(argv[1]) == "--no-writes";
  if (no_writes) {
    --argc;
    ++argv;
  }
  if (argc < 3) {
    std::fputs("usage: grade-confine [--no-writes] HOME PROGRAM [ARGS...]\n", stderr);
    return 2;
  }
  const rlimit threads{kMaxThreads, kMaxThreads};
  setrlimit(RLIMIT_NPROC, &threads);
  if (!load_filter(no_writes)) {
    std::perror("grade-confine: cannot load the seccomp filter that keeps a case to one process");
    return 126;
  }
  std::string home = std::string("HOME=") + argv[1];
  char path[] = "PATH=/usr/bin:/bin";
  char lang[] = "LANG=C";
#if defined(__SANITIZE_ADDRESS__)
  // LeakSanitizer checks at exit from a process it starts and traces, which the filter refuses:
  // in a sanitized build, the kernels keep the sanitizer's other options but leave leaks unchecked.
  const char* given = std::getenv("ASAN_OPTIONS");
  std::string asan =
      std::string("ASAN_OPTIONS=") + (given != nullptr ? given : "") + ":detect_leaks=0";
  char* env[] = {path, lang, home.data(), asan.data(), nullptr};
#else
  char* env[] = {path, lang, home.data(), nullptr};
#endif
  execve(argv[2], argv + 2, env);
  std::perror("grade-confine: cannot execute the kernels program");
  return 127;
}
