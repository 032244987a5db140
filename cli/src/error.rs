//! Errors of the command-line program and their exit codes.

use std::fmt;
use std::path::Path;

use yarnsim::{SceneError, SimError};

/// Exit code of a run that was interrupted by Ctrl-C (128 + SIGINT), SIGTERM or SIGHUP.
pub const EXIT_INTERRUPTED: u8 = 130;

/// Why a command failed. Each kind has its own exit code, see [`CliError::exit_code`].
#[derive(Debug)]
pub enum CliError {
    /// A bad command-line value that clap could not catch (exit code 2, like clap's own errors).
    Usage(String),
    /// Unknown scene name, unreadable or invalid scene file (exit code 3).
    Scene(SceneError),
    /// An output file cannot be created or written (exit code 4).
    Output { path: String, message: String },
    /// A viewer cannot be started or reached, or standard output fails (exit code 4).
    Viewer(String),
    /// The simulation diverged or refused its input (exit code 1).
    Sim(SimError),
    /// A yarn simulation diverged, with a hint at the stable step (exit code 1).
    Diverged { error: SimError, hint: String },
    /// Another simulation failure, e.g. a mass-spring solver (exit code 1).
    Failed(String),
}

impl CliError {
    /// The process exit code for this error.
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Sim(_) | CliError::Diverged { .. } | CliError::Failed(_) => 1,
            CliError::Usage(_) => 2,
            CliError::Scene(_) => 3,
            CliError::Output { .. } | CliError::Viewer(_) => 4,
        }
    }

    /// An output error about `path`.
    pub fn output(path: &Path, message: impl fmt::Display) -> Self {
        CliError::Output {
            path: path.display().to_string(),
            message: message.to_string(),
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Usage(m) => write!(f, "{m}"),
            CliError::Scene(e) => write!(f, "{e}"),
            CliError::Output { path, message } => {
                write!(f, "cannot write output file {path}: {message}")
            }
            CliError::Viewer(m) => write!(f, "{m}"),
            CliError::Sim(e) => write!(f, "{e}"),
            CliError::Diverged { error, hint } => write!(f, "{error}; {hint}"),
            CliError::Failed(m) => write!(f, "{m}"),
        }
    }
}

impl std::error::Error for CliError {}

impl From<SceneError> for CliError {
    fn from(e: SceneError) -> Self {
        CliError::Scene(e)
    }
}

impl From<SimError> for CliError {
    fn from(e: SimError) -> Self {
        CliError::Sim(e)
    }
}
