// The header compiles as C++ (extern "C" guards) and the library is callable
// from C++: RAII ownership of a handle, a std::vector as the caller's buffer.
#include "meshless_impact.h"

#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace {
struct SimFree {
    void operator()(mi_sim *s) const { mi_sim_free(s); }
};
using Sim = std::unique_ptr<mi_sim, SimFree>;

bool ok(mi_result r, const char *what) {
    if (r != MI_OK) std::fprintf(stderr, "%s: %s\n", what, mi_result_name(r));
    return r == MI_OK;
}
}  // namespace

int main() {
    if (std::string(mi_version()) != MI_VERSION) return 1;
    mi_sim *raw = nullptr;
    if (!ok(mi_sim_new("taylor", &raw), "mi_sim_new")) return 1;
    Sim sim(raw);
    if (!ok(mi_sim_set_param(sim.get(), "particles_radial", 5), "set")) return 1;
    if (!ok(mi_sim_advance_to(sim.get(), 5e-6), "advance_to")) return 1;
    size_t n = 0;
    if (!ok(mi_sim_history_times(sim.get(), nullptr, 0, &n), "history size")) return 1;
    std::vector<double> times(n), length(n);
    if (!ok(mi_sim_history_times(sim.get(), times.data(), times.size(), nullptr), "times")) return 1;
    if (!ok(mi_sim_history(sim.get(), "rod_length", length.data(), length.size(), nullptr),
            "history"))
        return 1;
    if (n < 2 || !(length.back() < length.front())) return 1;
    std::printf("C++: %zu history rows, rod_length %.6g -> %.6g m at t = %.3g s\n", n,
                length.front(), length.back(), times.back());
    if (mi_sim_set_param(sim.get(), "impact_speed", 100) != MI_WRONG_ORDER) return 1;
    return 0;
}
