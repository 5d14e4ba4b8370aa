//! The browsers connected to a studio: one bounded queue of frames each.
//! Offering a frame never waits: a full queue (a slow browser) loses the
//! frame, counted for that browser and in total; a closed one is removed.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender, TrySendError};
use std::sync::{Arc, Mutex};

/// Frames a browser may have waiting before new ones are dropped (about
/// 0.4 s at 20 frames per second).
pub(crate) const QUEUE_FRAMES: usize = 8;

/// The most browsers served at once.
pub(crate) const MAX_CLIENTS: usize = 8;

struct Client {
    tx: SyncSender<Arc<str>>,
    drops: Arc<AtomicU64>,
}

/// Every connected browser.
#[derive(Default)]
pub(crate) struct Hub {
    clients: Mutex<Vec<Client>>,
    /// Frames dropped over all browsers.
    pub drops: AtomicU64,
    /// Frames offered.
    pub frames: AtomicU64,
}

impl Hub {
    /// Adds a browser: its queue's receiving end and its drop counter; `None`
    /// when [`MAX_CLIENTS`] are connected.
    pub fn join(&self) -> Option<(Receiver<Arc<str>>, Arc<AtomicU64>)> {
        let mut c = self.clients.lock().unwrap_or_else(|e| e.into_inner());
        if c.len() >= MAX_CLIENTS {
            return None;
        }
        let (tx, rx) = sync_channel(QUEUE_FRAMES);
        let drops = Arc::new(AtomicU64::new(0));
        c.push(Client { tx, drops: drops.clone() });
        Some((rx, drops))
    }

    /// Offers `frame` to every browser without waiting.
    pub fn broadcast(&self, frame: Arc<str>) {
        self.frames.fetch_add(1, Ordering::Relaxed);
        let mut c = self.clients.lock().unwrap_or_else(|e| e.into_inner());
        c.retain(|cl| match cl.tx.try_send(frame.clone()) {
            Ok(()) => true,
            Err(TrySendError::Full(_)) => {
                cl.drops.fetch_add(1, Ordering::Relaxed);
                self.drops.fetch_add(1, Ordering::Relaxed);
                true
            }
            Err(TrySendError::Disconnected(_)) => false,
        });
    }

    /// Browsers connected.
    pub fn len(&self) -> usize {
        self.clients.lock().unwrap_or_else(|e| e.into_inner()).len()
    }

    /// Closes every queue (their connections end).
    pub fn close(&self) {
        self.clients.lock().unwrap_or_else(|e| e.into_inner()).clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_browser_that_does_not_read_loses_frames_and_never_blocks() {
        let hub = Hub::default();
        let (rx, drops) = hub.join().unwrap();
        for i in 0..QUEUE_FRAMES + 5 {
            hub.broadcast(Arc::from(format!("{i}")));
        }
        assert_eq!(drops.load(Ordering::Relaxed), 5);
        assert_eq!(hub.drops.load(Ordering::Relaxed), 5);
        assert_eq!(&*rx.recv().unwrap(), "0", "the oldest frames are kept, in order");
        drop(rx);
        hub.broadcast(Arc::from("x"));
        assert_eq!(hub.len(), 0, "a vanished browser is removed");
    }

    #[test]
    fn at_most_max_clients() {
        let hub = Hub::default();
        let held: Vec<_> = (0..MAX_CLIENTS).map(|_| hub.join().unwrap()).collect();
        assert!(hub.join().is_none());
        drop(held);
    }
}
