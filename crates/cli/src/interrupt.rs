//! Ctrl-C and SIGTERM: the state the signal handler shares with the run, and what a signal
//! does at each point of it.

use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};

/// Where a run is, so that Ctrl-C does the right thing at each point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Phase {
    /// Reading and building the scene: nothing to clean up, so Ctrl-C exits at once.
    Loading = 0,
    /// Rendering: Ctrl-C cancels within a fraction of a second (the renderer asks inside
    /// pixels); a second one exits at once
    /// (rendering writes nothing, so that is safe too).
    Rendering = 1,
    /// Writing the image: Ctrl-C is noted but the (atomic) write completes, so that no
    /// temporary file is left behind.
    Writing = 2,
}

/// What the Ctrl-C handler should do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SignalAction {
    ExitNow,
    Cancel,
    Ignore,
}

/// The state shared between the Ctrl-C handler and the run. Const-constructible, so `main` can
/// keep it in a `static` that the handler (which must be `'static`) reads.
#[derive(Debug)]
pub struct Interrupt {
    phase: AtomicU8,
    requested: AtomicBool,
}

impl Default for Interrupt {
    fn default() -> Self {
        Interrupt::new()
    }
}

impl Interrupt {
    pub const fn new() -> Interrupt {
        Interrupt {
            phase: AtomicU8::new(Phase::Loading as u8),
            requested: AtomicBool::new(false),
        }
    }

    pub fn set_phase(&self, phase: Phase) {
        self.phase.store(phase as u8, Ordering::SeqCst);
    }

    fn phase(&self) -> Phase {
        match self.phase.load(Ordering::SeqCst) {
            0 => Phase::Loading,
            1 => Phase::Rendering,
            _ => Phase::Writing,
        }
    }

    /// Whether Ctrl-C was pressed.
    pub fn requested(&self) -> bool {
        self.requested.load(Ordering::SeqCst)
    }

    /// Records a Ctrl-C and says what to do about it.
    pub fn on_signal(&self) -> SignalAction {
        let again = self.requested.swap(true, Ordering::SeqCst);
        match self.phase() {
            Phase::Loading => SignalAction::ExitNow,
            Phase::Rendering if again => SignalAction::ExitNow,
            Phase::Rendering => SignalAction::Cancel,
            Phase::Writing => SignalAction::Ignore,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ctrl_c_exits_while_loading_cancels_while_rendering_and_waits_for_the_write() {
        let interrupt = Interrupt::new();
        assert_eq!(interrupt.on_signal(), SignalAction::ExitNow);

        let interrupt = Interrupt::new();
        interrupt.set_phase(Phase::Rendering);
        assert!(!interrupt.requested());
        assert_eq!(interrupt.on_signal(), SignalAction::Cancel);
        assert!(interrupt.requested());
        assert_eq!(interrupt.on_signal(), SignalAction::ExitNow);

        let interrupt = Interrupt::new();
        interrupt.set_phase(Phase::Writing);
        assert_eq!(interrupt.on_signal(), SignalAction::Ignore);
        assert_eq!(interrupt.on_signal(), SignalAction::Ignore);
        assert!(interrupt.requested());
    }
}
