//! Resource guards: what a model's workspace and a run's samples will take, estimated before
//! anything is allocated, against the memory the machine has (an allocation failure aborts the
//! process, past any error handling).

/// The bytes a model or a run may use: half the memory available now (Linux: `MemAvailable` of
/// /proc/meminfo, or the address-space limit if lower), else 8 GB.
pub fn memory_budget() -> f64 {
    let available = std::fs::read_to_string("/proc/meminfo").ok().and_then(|text| {
        text.lines()
            .find(|l| l.starts_with("MemAvailable:"))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|kb| kb.parse::<f64>().ok())
            .map(|kb| kb * 1024.0)
    });
    // a process address-space limit (ulimit -v) caps it too: past it an allocation aborts
    let limit = std::fs::read_to_string("/proc/self/limits").ok().and_then(|text| {
        text.lines()
            .find(|l| l.starts_with("Max address space"))
            .and_then(|l| l.split_whitespace().nth(3))
            .and_then(|v| v.parse::<f64>().ok())
    });
    0.5 * available.unwrap_or(16e9).min(limit.unwrap_or(f64::INFINITY))
}

/// Bytes of the dense matrices of a model's workspace ([`crate::data::Data`]): the mass matrix
/// (and its factor with constraints), `G` and `M⁻¹Gᵀ`, the constraint Schur complement, plus
/// about 2 kB per body.
pub fn workspace_bytes(nbodies: usize, nu: usize, nc: usize) -> f64 {
    let (nu, nc, nb) = (nu as f64, nc as f64, nbodies as f64);
    let factor = if nc > 0.0 { nu * nu } else { 0.0 };
    8.0 * (nu * nu + factor + 2.0 * nc * nu + nc * nc) + 2048.0 * nb
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn estimates_grow_with_the_dense_parts_and_the_budget_is_positive() {
        assert!(memory_budget() > 1e6);
        // 40 000 bodies on free joints: the dense mass matrix alone is 8 (240 000)² bytes
        let big = workspace_bytes(40_001, 240_000, 0);
        assert!((big - (8.0 * 240_000f64.powi(2) + 2048.0 * 40_001.0)).abs() < 1.0);
        assert!(workspace_bytes(3, 2, 1) < workspace_bytes(3, 2, 2));
    }
}
