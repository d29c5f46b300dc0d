#include "vtk_series.hpp"

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "fibernet/network/network_io.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet::cli {

std::string VtkSeries::file_of(int step) const {
    char name[32];
    std::snprintf(name, sizeof name, "step_%06d.vtp", step);
    return name;
}

void VtkSeries::open(int keep_steps, const std::vector<std::pair<int, double>>& kept_rows) {
    std::error_code ec;
    std::filesystem::create_directories(dir_, ec);
    if (ec) throw InputError("--vtk '" + dir_ + "': cannot create the directory (" + ec.message() + ")");
    steps_.clear();
    for (const auto& [step, t] : kept_rows)
        if (step <= keep_steps && std::filesystem::exists(dir_ + "/" + file_of(step), ec))
            steps_.push_back({t, file_of(step)});
}

void VtkSeries::add(int step, double t, const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                    const VtpFields& fields) {
    std::ostringstream vtp, pvd;
    write_vtp(vtp, e, q, F, fields);
    write_file_atomic(dir_ + "/" + file_of(step), vtp.str());
    steps_.push_back({t, file_of(step)});
    write_pvd(pvd, steps_);
    write_file_atomic(dir_ + "/series.pvd", pvd.str());
}

}  // namespace fibernet::cli
