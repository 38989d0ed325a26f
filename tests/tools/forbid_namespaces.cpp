// forbid_namespaces: runs a command as a container that forbids namespaces would run it.
//
//   forbid_namespaces COMMAND [ARGS...]
//
// Docker's default seccomp profile, for a container without CAP_SYS_ADMIN (as Gradescope's are
// by default), refuses the calls that make or enter a namespace or mount a file system: clone
// with a namespace flag, unshare, setns, mount, umount2, pivot_root and the new mount API fail
// with EPERM, and clone3 with ENOSYS (its flags are in memory, where a filter cannot read them,
// so the C library falls back to clone). This program loads that part of the profile, gives up
// CAP_SYS_ADMIN, and runs COMMAND, which, with everything it starts, stays so.
// tests/tools/try-gradescope-root.sh runs the autograder under it to see what the grader's
// sandbox (bubblewrap, which needs a user namespace) does there. It is a tool for that script
// alone, built by it, and part of no build of the project.
#include <linux/audit.h>
#include <linux/capability.h>
#include <linux/filter.h>
#include <linux/seccomp.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <vector>

namespace {

#if defined(__x86_64__)
constexpr unsigned kArch = AUDIT_ARCH_X86_64;
#elif defined(__aarch64__)
constexpr unsigned kArch = AUDIT_ARCH_AARCH64;
#else
#error "forbid_namespaces knows the system calls of x86-64 and AArch64 only"
#endif

// Every namespace flag clone takes (Docker's profile allows clone when none is set).
constexpr unsigned kNamespaceFlags = CLONE_NEWNS | CLONE_NEWUTS | CLONE_NEWIPC | CLONE_NEWUSER |
                                     CLONE_NEWPID | CLONE_NEWNET | CLONE_NEWCGROUP;

sock_filter op(unsigned short code, unsigned k, unsigned char yes = 0, unsigned char no = 0) {
  return sock_filter{code, yes, no, k};
}

bool load_filter() {
  const unsigned refuse = SECCOMP_RET_ERRNO | EPERM;
  std::vector<sock_filter> f = {
      op(BPF_LD | BPF_W | BPF_ABS, offsetof(seccomp_data, arch)),
      op(BPF_JMP | BPF_JEQ | BPF_K, kArch, 1, 0),
      op(BPF_RET | BPF_K, refuse),  // another architecture's numbering: refused whole
      op(BPF_LD | BPF_W | BPF_ABS, offsetof(seccomp_data, nr)),
  };
  for (const long nr :
       {SYS_unshare, SYS_setns, SYS_mount, SYS_umount2, SYS_pivot_root, SYS_fsopen, SYS_fsmount,
        SYS_fsconfig, SYS_fspick, SYS_move_mount, SYS_open_tree, SYS_mount_setattr}) {
    f.push_back(op(BPF_JMP | BPF_JEQ | BPF_K, static_cast<unsigned>(nr), 0, 1));
    f.push_back(op(BPF_RET | BPF_K, refuse));
  }
  f.push_back(op(BPF_JMP | BPF_JEQ | BPF_K, SYS_clone3, 0, 1));
  f.push_back(op(BPF_RET | BPF_K, SECCOMP_RET_ERRNO | ENOSYS));
  // clone: its flags are the first argument (x86-64 and AArch64 alike); the low word holds them.
  f.push_back(op(BPF_JMP | BPF_JEQ | BPF_K, SYS_clone, 0, 3));
  f.push_back(op(BPF_LD | BPF_W | BPF_ABS, offsetof(seccomp_data, args[0])));
  f.push_back(op(BPF_JMP | BPF_JSET | BPF_K, kNamespaceFlags, 0, 1));
  f.push_back(op(BPF_RET | BPF_K, refuse));
  f.push_back(op(BPF_RET | BPF_K, SECCOMP_RET_ALLOW));
  const sock_fprog program{static_cast<unsigned short>(f.size()), f.data()};
  // Loaded while CAP_SYS_ADMIN is still held, as a container runtime does: no need for
  // no_new_privs, which Docker does not set either.
  return prctl(PR_SET_SECCOMP, SECCOMP_MODE_FILTER, &program) == 0;
}

// Gives up CAP_SYS_ADMIN for this process and all it runs, as Docker's containers lack it.
bool drop_sys_admin() {
  if (prctl(PR_CAPBSET_DROP, CAP_SYS_ADMIN, 0, 0, 0) != 0) return false;
  __user_cap_header_struct header{_LINUX_CAPABILITY_VERSION_3, 0};
  __user_cap_data_struct data[2]{};
  if (syscall(SYS_capget, &header, data) != 0) return false;
  const unsigned bit = 1U << (CAP_SYS_ADMIN % 32);
  auto& word = data[CAP_SYS_ADMIN / 32];
  word.effective &= ~bit;
  word.permitted &= ~bit;
  word.inheritable &= ~bit;
  return syscall(SYS_capset, &header, data) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: forbid_namespaces COMMAND [ARGS...]\n");
    return 2;
  }
  if (!load_filter()) {
    std::fprintf(stderr, "forbid_namespaces: loading the filter failed: %s\n",
                 std::strerror(errno));
    return 1;
  }
  if (!drop_sys_admin()) {
    std::fprintf(stderr, "forbid_namespaces: giving up CAP_SYS_ADMIN failed: %s\n",
                 std::strerror(errno));
    return 1;
  }
  execvp(argv[1], argv + 1);
  std::fprintf(stderr, "forbid_namespaces: %s: %s\n", argv[1], std::strerror(errno));
  return 127;
}
