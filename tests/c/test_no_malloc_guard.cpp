// The checked core build relies on EIGEN_NO_MALLOC with assertions on to
// abort on any Eigen heap allocation. This test proves that guard is live
// under the very flags pyins_core_checked uses: a dynamic-size matrix (heap)
// must abort; a fixed-size one (stack, as in the core) must not.
// Exit 0 only if both hold; any other outcome is a failure.
#include <Eigen/Dense>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <unistd.h>

static volatile std::sig_atomic_t g_phase = 0;   // 1 while the heap allocation is attempted

extern "C" void on_abort(int) {
    if (g_phase == 1) {
        static const char msg[] = "no-malloc guard fired on a heap allocation: OK\n";
        (void)!write(1, msg, sizeof msg - 1);
        _exit(0);
    }
    _exit(3);   // aborted somewhere else: a failure
}

int main() {
    std::signal(SIGABRT, on_abort);
    Eigen::Matrix<double, 8, 8> fixed = Eigen::Matrix<double, 8, 8>::Identity();
    fixed *= 2.0;
    std::printf("fixed-size matrix without the heap: trace %.1f\n", fixed.trace());
    g_phase = 1;
    Eigen::MatrixXd heap(16, 16);   // must trip eigen_assert(is_malloc_allowed)
    heap.setZero();
    g_phase = 0;
    std::printf("FAIL: a %ldx%ld heap matrix was allocated: the guard is off\n",
                static_cast<long>(heap.rows()), static_cast<long>(heap.cols()));
    return 1;
}
