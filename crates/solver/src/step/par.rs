//! The parallel loops and deterministic reductions the stages share.

use rayon::prelude::*;

/// Below this many items a loop runs on one thread (rayon's overhead would dominate).
pub(super) const PAR_MIN: usize = 1024;
/// Chunk size of the deterministic reductions (fixed, so sums do not depend on thread count).
pub(super) const SUM_CHUNK: usize = 2048;

/// Make `v` `n` long with every element `x`, unless it is `n` long already (then it is kept as it
/// is): no allocation once sized.
pub(super) fn resize<T: Clone>(v: &mut Vec<T>, n: usize, x: T) {
    if v.len() != n {
        v.clear();
        v.resize(n, x);
    }
}

/// Deterministic sum of `f(i)` for `i < n`: fixed chunks summed in parallel, then in order.
pub(super) fn det_sum(chunk: &mut Vec<f64>, n: usize, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    let chunks = n.div_ceil(SUM_CHUNK);
    resize(chunk, chunks, 0.0);
    let body = |(k, out): (usize, &mut f64)| {
        let end = ((k + 1) * SUM_CHUNK).min(n);
        *out = (k * SUM_CHUNK..end).map(&f).sum();
    };
    if n >= PAR_MIN {
        chunk.par_iter_mut().enumerate().for_each(body);
    } else {
        chunk.iter_mut().enumerate().for_each(body);
    }
    chunk.iter().sum()
}

/// `out[i] = f(i)` over a slice, in parallel above [`PAR_MIN`].
pub(super) fn fill<T: Send>(out: &mut [T], f: impl Fn(usize) -> T + Sync + Send) {
    if out.len() >= PAR_MIN {
        out.par_iter_mut().enumerate().for_each(|(i, o)| *o = f(i));
    } else {
        out.iter_mut().enumerate().for_each(|(i, o)| *o = f(i));
    }
}
