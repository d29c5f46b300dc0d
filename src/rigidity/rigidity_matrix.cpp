#include "fibernet/rigidity/rigidity_matrix.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace fibernet {

Eigen::MatrixXd rigidity_matrix(const BodyPinFramework& fw) {
    const long rows = fw.num_bars();
    Eigen::MatrixXd R = Eigen::MatrixXd::Zero(rows, 3 * fw.bodies);
    long row = 0;
    for (int k = 0; k < fw.num_pins(); ++k) {
        const Eigen::Vector2d p = fw.pin_point[k];
        const int b0 = fw.pin_body[fw.pin_offset[k]];
        for (int i = fw.pin_offset[k] + 1; i < fw.pin_offset[k + 1]; ++i) {
            const int b = fw.pin_body[i];
            // velocity of p on body c: (vx - omega p_y, vy + omega p_x)
            for (int c = 0; c < 2; ++c) {
                const double sign = c == 0 ? 1.0 : -1.0;
                const int body = c == 0 ? b0 : b;
                R(row, 3 * body + 0) += sign;
                R(row, 3 * body + 2) += -sign * p.y();
                R(row + 1, 3 * body + 1) += sign;
                R(row + 1, 3 * body + 2) += sign * p.x();
            }
            row += 2;
        }
    }
    return R;
}

DenseRigidity dense_rigidity(const BodyPinFramework& fw, double rel_cut) {
    DenseRigidity out;
    const int n = 3 * fw.bodies;
    if (n == 0) {
        out.d = fw.clamped ? 3 : -1;
        return out;
    }
    Eigen::MatrixXd R = rigidity_matrix(fw);
    // Pad with zero rows so the SVD gives the full right singular basis (null space included).
    if (R.rows() < n) R.conservativeResizeLike(Eigen::MatrixXd::Zero(n, n));
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(R, Eigen::ComputeFullV);
    out.singular_values = svd.singularValues();
    const double smax = out.singular_values.size() ? out.singular_values(0) : 0;
    out.cut = rel_cut * std::max(smax, 1.0);
    for (int i = 0; i < out.singular_values.size(); ++i) {
        const double s = out.singular_values(i);
        if (s > out.cut) ++out.rank, out.smallest_nonzero = s;
        else out.largest_zero = std::max(out.largest_zero, s);
    }
    out.nullity = n - out.rank;
    const Eigen::MatrixXd K = svd.matrixV().rightCols(out.nullity);  // null-space basis, orthonormal columns
    // Clusters: bodies whose 3 rows of K agree move together in every zero mode.
    out.cluster.assign(fw.bodies, -1);
    int next = 0;
    for (int a = 0; a < fw.bodies; ++a) {
        if (out.cluster[a] >= 0) continue;
        out.cluster[a] = next;
        for (int b = a + 1; b < fw.bodies; ++b)
            if (out.cluster[b] < 0 && (K.middleRows(3 * a, 3) - K.middleRows(3 * b, 3)).norm() <= 1e-7)
                out.cluster[b] = next;
        ++next;
    }
    if (fw.clamped) {
        // Zero modes with the bottom clamp at rest: the part of the null space with zero bottom rows.
        const Eigen::MatrixXd Kb = K.middleRows(3 * fw.bottom(), 3);
        Eigen::JacobiSVD<Eigen::MatrixXd> sb(Kb, Eigen::ComputeFullV);
        int rb = 0;
        for (int i = 0; i < sb.singularValues().size(); ++i) rb += sb.singularValues()(i) > 1e-7;
        const Eigen::MatrixXd Kg = K * sb.matrixV().rightCols(K.cols() - rb);
        out.d = 0;
        if (Kg.cols() > 0) {  // (an SVD of a 3 x 0 matrix is not defined in Eigen)
            Eigen::JacobiSVD<Eigen::MatrixXd> st(Kg.middleRows(3 * fw.top(), 3));
            for (int i = 0; i < st.singularValues().size(); ++i) out.d += st.singularValues()(i) > 1e-7;
        }
    }
    return out;
}

}  // namespace fibernet
