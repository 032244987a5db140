//! Logging through the environment's printf-style callback: the logger
//! type, the category indices and the escaping of pre-formatted messages.

use std::ffi::{c_char, c_int, c_void, CString};

#[allow(unused_imports)] // for the doc links
use crate::model_description::LOG_CATEGORIES;

/// The logger callback: `(componentEnvironment, instanceName, status, category, message, ...)`.
pub type Logger =
    unsafe extern "C" fn(*mut c_void, *const c_char, c_int, *const c_char, *const c_char, ...);

/// The FMI 3.0 logger callback `fmi3LogMessageCallback`:
/// `(instanceEnvironment, status, category, message)`, not variadic (the
/// message is plain text, no printf format).
pub type Logger3 = unsafe extern "C" fn(*mut c_void, c_int, *const c_char, *const c_char);

/// Log category indices into [`LOG_CATEGORIES`].
pub const LOG_EVENTS: usize = 0;
pub const LOG_WARNING: usize = 1;
pub const LOG_DISCARD: usize = 2;
pub const LOG_ERROR: usize = 3;
pub const LOG_FATAL: usize = 4;
pub const LOG_ALL: usize = 6;

/// Escapes a message for the printf-style logger: `%` as `%%`, `#` as `##`
/// (FMI variable references), and drops NUL bytes.
pub fn escape_log(msg: &str) -> CString {
    let mut s = String::with_capacity(msg.len() + 8);
    for c in msg.chars() {
        match c {
            '%' => s.push_str("%%"),
            '#' => s.push_str("##"),
            '\0' => {}
            c => s.push(c),
        }
    }
    CString::new(s).expect("NUL bytes removed")
}

/// A C string of `s` with NUL bytes dropped.
pub fn escape_nul(s: &str) -> CString {
    CString::new(s.replace('\0', "")).expect("NUL removed")
}
