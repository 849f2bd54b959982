//! What the report tells its caller as it goes (a command line shows it as a progress bar).

use crate::error::ReportError;

/// One event of a stage of the report: the materials, then the N sweep.
#[derive(Debug)]
pub enum Progress<'a> {
    /// A stage begins, with `len` steps.
    Start {
        /// The number of steps.
        len: usize,
    },
    /// The step now under way, in words (an input; "N sweep: " and an input).
    Step(&'a str),
    /// An input could not be reported; the others still go on.
    Failed(ReportError),
    /// The step is done.
    Done,
    /// The stage is over.
    Finish,
}
