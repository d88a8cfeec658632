// `mpirun -np N keithray view`: rank 0 opens the window and its render thread drives the
// other ranks through ViewRanks (viewer/render_worker.h, SharedPasses); every other rank runs
// serve_view_passes, a loop with no window. Rank 0 sends commands (app/cluster.h,
// broadcast_waiting): a job (the scene as saved, its settings), a full pass (the stop rule
// and the render region), or the end. Each pass runs through the one progressive driver with
// the rows dealt as for `render`, then rank 0 gathers the state: the image at N passes is the
// single-process viewer's, bit for bit. Previews are rank 0's alone. docs/scaling.md.
#pragma once

#include <memory>

#include "app/cluster.h"
#include "viewer/render_worker.h"

namespace kr {

// Rank 0's side. Its destructor (or finish) ends the other ranks' loops.
class ViewRanks final : public viewer::SharedPasses {
public:
    explicit ViewRanks(const Cluster& cluster);
    ~ViewRanks() override { finish(); }
    ViewRanks(const ViewRanks&) = delete;
    ViewRanks& operator=(const ViewRanks&) = delete;

    void start_job(const Scene& scene, const RenderSettings& settings, bool halves) override;
    std::string begin_pass(const StopRule& rule, const std::optional<viewer::PixelBox>& region) override;
    PassHooks& hooks() override { return *dealt_; }
    void end_pass(RenderState& state, uint64_t& rays, uint64_t& nonfinite) override;
    // A failed MPI call, or mpirun ending the job (its SIGCONT, a second before its SIGTERM).
    std::string lost() const override;
    // Ends the other ranks' loops; call once the render thread is gone.
    void finish();

private:
    const Cluster& cluster_;
    std::unique_ptr<PassHooks> dealt_;
    int width_ = 0, height_ = 0;  // of the job, for messages
    bool finished_ = false;
};

// Every rank other than 0: runs rank 0's commands until the end. Returns the exit status.
int serve_view_passes(const Cluster& cluster);

}  // namespace kr
