#include "fibernet/rigidity/compare.hpp"

#include "fibernet/network/clamp.hpp"
#include "fibernet/rigidity/body_pin.hpp"
#include "fibernet/rigidity/rigidity.hpp"

namespace fibernet {

RigidityComparison compare_rigidity(const Network& net, const DiscretizationParams& p, double zero_cut, double g_cut) {
    RigidityComparison c;
    c.fibers = static_cast<int>(net.fibers.size());
    c.crosslinks = net.num_crosslinks();
    {
        const RigidityResult r = analyze_rigidity(body_pin_framework(net));
        const Model m = discretize(net, p);
        const HessianSpectrum s = hessian_spectrum(m, zero_cut);
        c.dofs = 2 * m.num_nodes();
        c.floppy_modes = r.floppy_modes;
        c.nullity = s.nullity;
        c.largest_zero = s.largest_zero, c.smallest_nonzero = s.smallest_nonzero;
        c.nullity_agrees = c.floppy_modes == c.nullity;
    }
    {
        const ClampedNetwork cl = clamp_network(net);
        const RigidityResult r = analyze_rigidity(body_pin_framework(cl));
        const Model m = clamped_model(cl, p);
        const HessianSpectrum s = hessian_spectrum(m, zero_cut);
        int free_nodes = 0;
        for (char f : m.fixed) free_nodes += !f;
        c.clamped_dofs = 2 * free_nodes;
        c.d = r.d;
        c.G = clamped_shear_modulus(m, zero_cut);
        c.shear_agrees = (c.G > g_cut) == (r.d < 3);
        c.floppy_both_grounded = r.floppy_both_grounded;
        c.clamped_nullity = s.nullity;
        c.clamped_largest_zero = s.largest_zero, c.clamped_smallest_nonzero = s.smallest_nonzero;
        c.clamped_nullity_agrees = c.floppy_both_grounded == c.clamped_nullity;
    }
    return c;
}

}  // namespace fibernet
