// jprom from C++: RAII wrappers over the C API (handles freed by destructors, failed calls
// turned into exceptions carrying the status and message). Same model, sweep and JP workflow
// as sweep_example.c, same output tables.
//
// Build (from the repository root, after `cargo build --lib`):
//   g++ -Wall -Werror -std=c++17 -Iinclude examples-c/cpp_raii.cpp
//       -Ltarget/debug -ljprom -Wl,-rpath,$PWD/target/debug -o cpp_raii   (one line)
#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "jprom.h"

namespace jp {

// A failed jprom call: its status and the library's message.
struct Error : std::runtime_error {
    jprom_status status;
    Error(jprom_status s, const std::string &what)
        : std::runtime_error(what + ": " + jprom_status_name(static_cast<int>(s)) + ": " + jprom_last_error_message()),
          status(s) {}
};

inline void check(jprom_status s, const char *what) {
    if (s != JPROM_OK) throw Error(s, what);
}

// unique_ptr deleters calling the matching *_free (which accepts NULL).
struct ModelFree { void operator()(jprom_model *p) const { jprom_model_free(p); } };
struct SweepFree { void operator()(jprom_sweep_result *p) const { jprom_sweep_result_free(p); } };
struct BasisFree { void operator()(jprom_basis *p) const { jprom_basis_free(p); } };

// A JP basis: sizes n_h, h = 0..H.
class Basis {
  public:
    explicit Basis(jprom_basis *p) : p_(p) {}
    std::vector<size_t> sizes() const {
        size_t h = 0;
        std::vector<size_t> n(64);
        check(jprom_basis_sizes(p_.get(), n.data(), n.size(), &h), "jprom_basis_sizes");
        n.resize(h + 1);
        return n;
    }
    const jprom_basis *get() const { return p_.get(); }

  private:
    std::unique_ptr<jprom_basis, BasisFree> p_;
};

class Sweep {
  public:
    explicit Sweep(jprom_sweep_result *p) : p_(p) {}
    size_t size() const {
        size_t n = 0;
        check(jprom_sweep_result_n_points(p_.get(), &n), "jprom_sweep_result_n_points");
        return n;
    }
    double omega(size_t i) const {
        double w = 0;
        check(jprom_sweep_result_point_omega(p_.get(), i, &w), "jprom_sweep_result_point_omega");
        return w;
    }
    double amplitude(size_t i, size_t h, size_t output) const {
        double a = 0;
        check(jprom_sweep_result_point_amplitude(p_.get(), i, h, output, &a), "jprom_sweep_result_point_amplitude");
        return a;
    }
    // Error predictor e*_h of a reduced sweep's point.
    double predicted_error(size_t i, size_t h) const {
        double e = 0;
        check(jprom_sweep_result_point_predicted_error(p_.get(), i, h, &e), "jprom_sweep_result_point_predicted_error");
        return e;
    }
    size_t corrections() const {
        size_t n = 0;
        check(jprom_sweep_result_n_corrections(p_.get(), &n), "jprom_sweep_result_n_corrections");
        return n;
    }
    // Whether correction i was swept over the band (false: judged at screening points only).
    bool correction_swept(size_t i) const {
        int swept = 0;
        check(jprom_sweep_result_correction_swept(p_.get(), i, &swept), "jprom_sweep_result_correction_swept");
        return swept != 0;
    }
    // Why the corrections of a self-correcting sweep ended, and the judged error of its last pass.
    std::pair<jprom_correction_end, double> correction_end() const {
        jprom_correction_end end = JPROM_CORRECTIONS_WITHIN_THRESHOLD;
        double judged = 0;
        check(jprom_sweep_result_correction_end(p_.get(), &end, &judged), "jprom_sweep_result_correction_end");
        return {end, judged};
    }

    // The linearised error of the static contact displacement at the final pass' checks
    // (reported, not judged: docs/formulation.md §10.6); empty for a sweep without checks.
    std::optional<double> static_error() const {
        double e = 0;
        if (jprom_sweep_result_static_error(p_.get(), &e) != JPROM_OK) return std::nullopt;
        return e;
    }

  private:
    std::unique_ptr<jprom_sweep_result, SweepFree> p_;
};

class Model {
  public:
    // Dense column-major n x n mass and stiffness.
    Model(size_t n, const std::vector<double> &mass, const std::vector<double> &stiffness) {
        if (mass.size() != n * n || stiffness.size() != n * n) throw std::invalid_argument("matrix sizes");
        jprom_model *p = nullptr;
        check(jprom_model_new(n, mass.data(), stiffness.data(), &p), "jprom_model_new");
        p_.reset(p);
    }
    void add_ground_contact(const size_t dofs[3], const double frame[9], double kt1, double kt2, double kn,
                            double mu, double n0) {
        check(jprom_model_add_contact_3d(p_.get(), dofs, nullptr, frame, kt1, kt2, kn, mu, n0),
              "jprom_model_add_contact_3d");
    }
    void set_rayleigh_damping(double alpha, double beta) {
        check(jprom_model_set_rayleigh_damping(p_.get(), alpha, beta), "jprom_model_set_rayleigh_damping");
    }
    void set_harmonic_force(size_t h, const std::vector<double> &cos_part, const std::vector<double> &sin_part) {
        check(jprom_model_set_harmonic_force(p_.get(), h, cos_part.data(), sin_part.data(), cos_part.size()),
              "jprom_model_set_harmonic_force");
    }
    void set_output_dofs(const std::vector<size_t> &dofs) {
        check(jprom_model_set_output_dofs(p_.get(), dofs.data(), dofs.size()), "jprom_model_set_output_dofs");
    }
    // Sweeps without a callback.
    Sweep sweep(const jprom_hbm_options &opts, const jprom_sweep_options &band) const {
        jprom_sweep_result *s = nullptr;
        check(jprom_sweep(p_.get(), &opts, &band, nullptr, nullptr, &s), "jprom_sweep");
        return Sweep(s);
    }
    // A JP basis predicted for the band between omega_start and omega_end.
    Basis predict_basis(const jprom_hbm_options &opts, const jprom_jp_options &jp, double omega_start, double omega_end) const {
        jprom_basis *b = nullptr;
        check(jprom_basis_predict_opts(p_.get(), &opts, &jp, omega_start, omega_end, &b), "jprom_basis_predict_opts");
        return Basis(b);
    }
    // The self-correcting reduced sweep (kind JPROM_ROM_FR or JPROM_ROM_NLR) and its final basis.
    std::pair<Sweep, Basis> sweep_adaptive(int kind, const jprom_hbm_options &opts, const jprom_sweep_options &band,
                                           const jprom_jp_options &jp) const {
        jprom_sweep_result *s = nullptr;
        jprom_basis *b = nullptr;
        check(jprom_rom_sweep_adaptive(p_.get(), kind, &opts, &band, &jp, nullptr, nullptr, &s, &b), "jprom_rom_sweep_adaptive");
        return {Sweep(s), Basis(b)};
    }

  private:
    std::unique_ptr<jprom_model, ModelFree> p_;
};

}  // namespace jp

int main() {
    const size_t n = 6;  // node 0 (x, y, z) then node 1 (x, y, z)
    std::vector<double> mass(n * n, 0.0), stiffness(n * n, 0.0);
    for (size_t d = 0; d < 3; ++d) {
        const size_t a = d, b = 3 + d;
        mass[a + a * n] = 1.0;
        mass[b + b * n] = 1.0;
        stiffness[a + a * n] = 2.0e4;
        stiffness[b + b * n] = 1.0e4;
        stiffness[a + b * n] = -1.0e4;
        stiffness[b + a * n] = -1.0e4;
    }
    try {
        jp::Model model(n, mass, stiffness);
        const size_t node1[3] = {3, 4, 5};
        const double frame[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        model.add_ground_contact(node1, frame, 3.0e4, 3.0e4, 5.0e4, 0.5, 20.0);
        model.set_rayleigh_damping(0.0, 1.0e-4);
        model.set_harmonic_force(1, {5.0, 0, 0, 0, 0, 0}, std::vector<double>(n, 0.0));
        model.set_output_dofs({0, 3});

        jprom_hbm_options opts;
        jprom_sweep_options band;
        jp::check(jprom_hbm_options_default(&opts), "jprom_hbm_options_default");
        jp::check(jprom_sweep_options_default(&band), "jprom_sweep_options_default");
        opts.harmonics = 3;
        band.omega_start = 60.0;
        band.omega_end = 160.0;

        const jp::Sweep sweep = model.sweep(opts, band);
        std::printf("# jprom %s from C++, %zu points\n", jprom_version(), sweep.size());
        std::printf("# index omega_rad_s X1_node0_x X1_node1_x\n");
        for (size_t i = 0; i < sweep.size(); ++i)
            std::printf("%zu %.10e %.10e %.10e\n", i, sweep.omega(i), sweep.amplitude(i, 1, 0), sweep.amplitude(i, 1, 1));

        // A failed call throws, and every handle made so far is still released.
        try {
            sweep.omega(sweep.size());
            std::fprintf(stderr, "expected an exception\n");
            return 1;
        } catch (const jp::Error &e) {
            if (e.status != JPROM_INVALID_VALUE) return 1;
            std::printf("# out-of-range point rejected: %s\n", e.what());
        }

        // Jacobian Projection: predicted basis, then the self-correcting NLR sweep.
        jprom_jp_options jp;
        jp::check(jprom_jp_options_default(&jp), "jprom_jp_options_default");
        const std::vector<size_t> predicted = model.predict_basis(opts, jp, band.omega_start, band.omega_end).sizes();
        std::printf("# JP: predicted basis sizes n_h, h = 0..%zu:", predicted.size() - 1);
        for (size_t n_h : predicted) std::printf(" %zu", n_h);
        std::printf("\n");
        const auto rom = model.sweep_adaptive(JPROM_ROM_NLR, opts, band, jp);
        const jp::Sweep &reduced = rom.first;
        size_t swept = 0;
        for (size_t i = 0; i < reduced.corrections(); ++i) swept += reduced.correction_swept(i) ? 1 : 0;
        std::printf("# JP: self-correcting NLR sweep, %zu points, %zu corrections (%zu swept), final n_1 = %zu\n", reduced.size(),
                    reduced.corrections(), swept, rom.second.sizes()[1]);
        const auto ended = reduced.correction_end();
        std::printf("# JP: corrections ended: %s, judged error %.3g (threshold %g)\n", jprom_correction_end_name(ended.first), ended.second,
                    jp.threshold);
        if (const auto w0 = reduced.static_error()) std::printf("# JP: static contact displacement error %.6e\n", *w0);
        std::printf("# index omega_rad_s X1_node0_x X1_node1_x e_star_1\n");
        for (size_t i = 0; i < reduced.size(); ++i)
            std::printf("%zu %.10e %.10e %.10e %.10e\n", i, reduced.omega(i), reduced.amplitude(i, 1, 0), reduced.amplitude(i, 1, 1),
                        reduced.predicted_error(i, 1));
    } catch (const std::exception &e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
    return 0;
}
