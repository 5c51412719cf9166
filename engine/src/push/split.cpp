// The single frame push factor: `--push split`, the paper's Sec. 8.1.
//
// Two solves of A lambda = b (Eq. 6.2.9) over the same rows: the first with each row's target
// with the push (as Baumgarte, Sec. 5.3) gives f_cv = f_ext + J^T lambda; the second without it
// gives f_c0 = f_ext + J^T lambda_0. The positions move with f_cv (Eqs. 3.2.3-3.2.4) and the stored
// momenta with f_c0 (Eqs. 3.2.1-3.2.2): the error is corrected within the frame and the velocity
// that corrected it is not kept.
//
// With warm starting (Sec. 6.2.3) each solve starts from its own lambda of the previous step:
// they solve for different targets, and a persisting contact's lambda of one solve is the guess
// closest to that solve's answer. Starting the second from the first's lambda would begin from
// the push's correction, which Sec. 8.1 keeps out of the stored momenta; with a fixed number of
// sweeps some of it would stay there.

#include "push_method.h"

namespace cps {
namespace {

class SingleFramePush final : public PushMethod {
 public:
  void step(StepContext& ctx) override {
    ctx.solve(TargetTerms::push_and_bias, ctx.lambda, ctx.f_cv, ctx.warm_guess());  // Sec. 7
    ctx.solve(TargetTerms::bias_only, ctx.lambda_second, ctx.f_c0,                  // Sec. 8.1
              ctx.warm() && !ctx.initial_second.empty() ? &ctx.initial_second : nullptr);
    ctx.store_warm_start();
    ctx.integrate(ctx.f_cv, ctx.f_c0, ctx.def->dt);  // Sec. 3.2
  }
};

}  // namespace

std::unique_ptr<PushMethod> make_single_frame_push() {
  return std::make_unique<SingleFramePush>();
}

}  // namespace cps
