#pragma once
/// \file
/// libtorch's intra-op thread count. Linking this room also registers libtorch as the compute
/// runtime of core/environment.hpp, so env.json and `skinlab --version` report its version and
/// thread count.

namespace skinlab {

/// Number of intra-op threads libtorch uses.
int torch_threads();

/// Sets libtorch's intra-op threads: `n`, or every hardware thread when `n` is 0. (OpenMP's own
/// default is not reliable in containers: on our 2-core CI machine it picks 1.) Returns the
/// count in effect. Error for n < 0.
int set_torch_threads(int n);

}  // namespace skinlab
