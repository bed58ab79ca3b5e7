//! Validation message capture: the debug messenger's callback and the log it fills.

use std::ffi::{c_void, CStr};
use std::sync::{Arc, Mutex};

use ash::vk;

/// Severity of a captured validation message.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Severity {
    /// Informational; never captured into a [`ValidationLog`].
    Info,
    /// A warning (includes performance warnings).
    Warning,
    /// An error: invalid API usage, a synchronization hazard or a leaked object.
    Error,
}

/// One message from `VK_LAYER_KHRONOS_validation`.
#[derive(Debug, Clone)]
pub struct ValidationMessage {
    /// How severe.
    pub severity: Severity,
    /// The message ID name (`VUID-...`, `SYNC-HAZARD-...`), possibly empty.
    pub id: String,
    /// The full message text.
    pub text: String,
}

impl std::fmt::Display for ValidationMessage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "[{:?}] {}: {}", self.severity, self.id, self.text)
    }
}

/// Collects validation warnings and errors of a headless context.
///
/// Clone it into [`crate::ContextOptions::validation_log`] and inspect it after the
/// context is dropped: messages emitted while the device and instance are destroyed
/// (such as objects still alive at `vkDestroyDevice`) are captured too.
#[derive(Debug, Clone, Default)]
pub struct ValidationLog {
    inner: Arc<Mutex<Vec<ValidationMessage>>>,
}

impl ValidationLog {
    /// A new, empty log.
    pub fn new() -> Self {
        Self::default()
    }

    /// A copy of every message captured so far.
    pub fn messages(&self) -> Vec<ValidationMessage> {
        self.lock().clone()
    }

    /// Removes and returns every message captured so far.
    pub fn take(&self) -> Vec<ValidationMessage> {
        std::mem::take(&mut *self.lock())
    }

    /// True when no warning or error has been captured.
    pub fn is_empty(&self) -> bool {
        self.lock().is_empty()
    }

    /// Panics listing every captured message, if there is any.
    ///
    /// Meant for tests: call it after dropping the context.
    #[track_caller]
    pub fn assert_clean(&self) {
        let messages = self.take();
        if !messages.is_empty() {
            let list = messages.iter().map(|m| format!("  {m}")).collect::<Vec<_>>().join("\n");
            panic!("{} Vulkan validation message(s):\n{list}", messages.len());
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<ValidationMessage>> {
        // A panic while the lock was held leaves plain data behind: keep using it.
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The pointer handed to Vulkan as callback user data. The caller keeps a clone
    /// of `self` alive for as long as the messenger (and the instance) lives.
    pub(crate) fn user_data(&self) -> *mut c_void {
        Arc::as_ptr(&self.inner) as *mut c_void
    }
}

/// The debug-utils messenger callback: records warnings/errors, never panics.
///
/// # Safety
/// Called by the Vulkan loader with `user_data` from [`ValidationLog::user_data`].
pub(crate) unsafe extern "system" fn messenger_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user_data: *mut c_void,
) -> vk::Bool32 {
    let result = std::panic::catch_unwind(|| {
        if data.is_null() || user_data.is_null() {
            return;
        }
        // SAFETY: the loader passes a valid callback-data struct for the duration of the call.
        let data = unsafe { &*data };
        let text = |p: *const std::ffi::c_char| {
            if p.is_null() {
                String::new()
            } else {
                // SAFETY: non-null strings in the callback data are NUL-terminated.
                unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
            }
        };
        let severity = if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
            Severity::Error
        } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
            Severity::Warning
        } else {
            Severity::Info
        };
        let message = ValidationMessage { severity, id: text(data.p_message_id_name), text: text(data.p_message) };
        match severity {
            Severity::Error => log::error!("vulkan: {message}"),
            Severity::Warning => log::warn!("vulkan: {message}"),
            Severity::Info => log::debug!("vulkan: {message}"),
        }
        if severity >= Severity::Warning {
            // SAFETY: user_data is the Arc'd mutex of a ValidationLog kept alive by
            // the device record until after the instance is destroyed.
            let inner = unsafe { &*(user_data as *const Mutex<Vec<ValidationMessage>>) };
            inner.lock().unwrap_or_else(|e| e.into_inner()).push(message);
        }
    });
    let _ = result;
    vk::FALSE
}

/// Create-info for the messenger, shared by instance creation (pNext) and the messenger itself.
pub(crate) fn messenger_info(log: &ValidationLog) -> vk::DebugUtilsMessengerCreateInfoEXT<'static> {
    vk::DebugUtilsMessengerCreateInfoEXT::default()
        .message_severity(
            vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
                | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                | vk::DebugUtilsMessageSeverityFlagsEXT::INFO,
        )
        .message_type(
            vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
        )
        .pfn_user_callback(Some(messenger_callback))
        .user_data(log.user_data())
}
