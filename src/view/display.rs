//! Whether a window can be opened at all: `DISPLAY` (X11) or `WAYLAND_DISPLAY` (Wayland).

use std::ffi::OsString;

/// The display the viewer will open its window on, from the values of `DISPLAY` and
/// `WAYLAND_DISPLAY` (an empty value counts as unset); `None` without either.
pub fn display_name(display: Option<OsString>, wayland: Option<OsString>) -> Option<String> {
    let set = |v: Option<OsString>| v.filter(|v| !v.is_empty()).map(|v| v.to_string_lossy().into_owned());
    match (set(wayland), set(display)) {
        (Some(w), _) => Some(format!("Wayland display {w}")),
        (None, Some(x)) => Some(format!("X display {x}")),
        (None, None) => None,
    }
}

/// [`display_name`] of this process's environment.
pub fn current_display() -> Option<String> {
    display_name(std::env::var_os("DISPLAY"), std::env::var_os("WAYLAND_DISPLAY"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn os(s: &str) -> Option<OsString> {
        Some(s.into())
    }

    #[test]
    fn no_display_without_either_variable() {
        assert_eq!(display_name(None, None), None);
        assert_eq!(display_name(os(""), os("")), None, "empty is unset");
    }

    #[test]
    fn x11_or_wayland_is_named() {
        assert_eq!(display_name(os(":1"), None).as_deref(), Some("X display :1"));
        assert_eq!(display_name(None, os("wayland-0")).as_deref(), Some("Wayland display wayland-0"));
        // winit prefers Wayland when both are set.
        assert_eq!(display_name(os(":1"), os("wayland-0")).as_deref(), Some("Wayland display wayland-0"));
    }
}
