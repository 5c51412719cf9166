// The push factor: `--push baumgarte`, the paper's Sec. 5.3 (Eqs. 5.2.3 and 5.3.1).
//
// Each violated row's target velocity carries the push beta d / dt (contacts, the depth d past
// the penetration slop) or -beta C / dt (rods, C the length error), added to its bias. One solve
// of A lambda = b (Eq. 6.2.9, Sec. 7) gives f_cv = f_ext + J^T lambda (Eq. 6.2.1), and both the
// positions and the stored momenta move with it (Sec. 3.2): the velocity that corrects the error
// stays in the momenta, which is what throws the intersecting stack apart (Sec. 10.2, Fig. 7 b).

#include "push_method.h"

namespace cps {
namespace {

class Baumgarte final : public PushMethod {
 public:
  void step(StepContext& ctx) override {
    ctx.solve(TargetTerms::push_and_bias, ctx.lambda, ctx.f_cv, ctx.warm_guess());  // Sec. 7
    ctx.lambda_second.clear();
    ctx.store_warm_start();
    ctx.integrate(ctx.f_cv, ctx.f_cv, ctx.def->dt);  // Sec. 3.2
  }
};

}  // namespace

std::unique_ptr<PushMethod> make_baumgarte() { return std::make_unique<Baumgarte>(); }

}  // namespace cps
