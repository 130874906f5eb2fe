//! The errors of `atelier-fit`.

/// What went wrong, with the field, position and value that caused it.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// A value out of its range, or sizes that do not agree.
    #[error("`{field}`[{index}] = {value}: {reason}")]
    Invalid {
        /// The field.
        field: &'static str,
        /// The position in it (a particle, segment, joint or shape).
        index: usize,
        /// The offending value (a count where sizes disagree).
        value: f64,
        /// Why.
        reason: String,
    },
    /// The static solve did not reach equilibrium.
    #[error(
        "no equilibrium after {iterations} Newton iterations: largest force {residual:e} N at particle {particle}"
    )]
    NoEquilibrium {
        /// Iterations made.
        iterations: usize,
        /// The largest remaining force on an inner particle, N.
        residual: f64,
        /// Where.
        particle: usize,
    },
    /// A file that cannot be read, does not parse or holds a value out of range (file,
    /// line:column, field).
    #[error(transparent)]
    File(#[from] atelier_files::FileError),
}

impl FitError {
    /// An [`FitError::Invalid`].
    pub fn invalid(
        field: &'static str,
        index: usize,
        value: f64,
        reason: impl Into<String>,
    ) -> Self {
        Self::Invalid {
            field,
            index,
            value,
            reason: reason.into(),
        }
    }
}
