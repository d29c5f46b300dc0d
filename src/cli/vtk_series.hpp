#pragma once
// A ParaView time series of a run's states: DIR/step_<n>.vtp per accepted step and DIR/series.pvd listing them with
// their strain as the time value (rewritten after each step, so an interrupted run leaves a readable series).
#include <string>
#include <utility>
#include <vector>

#include "fibernet/energy/network_energy.hpp"
#include "fibernet/export/vtp.hpp"

namespace fibernet::cli {

class VtkSeries {
public:
    explicit VtkSeries(std::string dir) : dir_(std::move(dir)) {}
    bool on() const { return !dir_.empty(); }
    // Creates the directory (InputError if it cannot be); on resume, the steps up to `keep_steps` already written
    // are listed again (their files are kept) and later ones dropped.
    void open(int keep_steps, const std::vector<std::pair<int, double>>& kept_rows);
    void add(int step, double t, const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
             const VtpFields& fields);

private:
    std::string file_of(int step) const;
    std::string dir_;
    std::vector<std::pair<double, std::string>> steps_;
};

}  // namespace fibernet::cli
