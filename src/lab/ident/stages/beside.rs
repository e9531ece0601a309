//! The two stages in order: one after the other, or stage 1's Newey–West
//! work on a thread of its own beside stage 2 (the same operations, so
//! the same figures bit for bit).

use super::super::regressors::{Differences, Spec};
use super::{FirstStage, Head, Solver};
use crate::error::Error;
use crate::ident::LeastSquaresFit;

/// A stage's fit, and with stage 1 what stage 2's errors need.
pub(in crate::lab::ident) type Solved = (LeastSquaresFit, Option<FirstStage>);

/// Stage 1 (from `head` when factored already) then stage 2 with `solver`.
pub(in crate::lab::ident) fn one_after_the_other<D: Differences>(
    mut solver: Solver,
    head: Option<Head>,
    [first_spec, second_spec]: [&Spec<'_, '_>; 2],
    k2_index: usize,
) -> Result<(Solved, Solved), Error> {
    let head = match head {
        Some(head) => head,
        None => solver.head::<D>(first_spec)?,
    };
    let influenced = solver.influence::<D>(first_spec, head)?;
    let first = solver.sums::<D>(first_spec, influenced, k2_index, None)?;
    let second = solver.solve::<D>(second_spec, 0, first.1.as_ref())?;
    Ok((first, second))
}

/// Stage 1's Newey–West work (from its `head`) on a thread of its own
/// while stage 2 is factored and its influence made beside it with
/// `second`; stage 2's sums then take stage 1's influence on `k2`. The
/// same operations as [`one_after_the_other`], so the same figures bit
/// for bit, and the same error: stage 1's first. `None` when no thread
/// could start.
pub(in crate::lab::ident) fn both_beside<D: Differences>(
    mut first: Solver,
    mut second: Solver,
    head: Head,
    [first_spec, second_spec]: [&Spec<'_, '_>; 2],
    k2_index: usize,
) -> Option<Result<(Solved, Solved), Error>> {
    std::thread::scope(|scope| {
        let stage1 = std::thread::Builder::new()
            .spawn_scoped(scope, move || {
                let influenced = first.influence::<D>(first_spec, head)?;
                first.sums::<D>(first_spec, influenced, k2_index, None)
            })
            .ok()?;
        let influenced = second
            .head::<D>(second_spec)
            .and_then(|head| second.influence::<D>(second_spec, head));
        let stage1 = stage1
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        Some(stage1.and_then(|first| {
            let solved = second.sums::<D>(second_spec, influenced?, 0, first.1.as_ref())?;
            Ok((first, solved))
        }))
    })
}
