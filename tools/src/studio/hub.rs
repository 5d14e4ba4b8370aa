//! The browsers connected to a studio: one bounded queue of frames each.
//! Offering a frame never waits: a full queue (a slow browser) loses the
//! frame, counted for that browser and in total; a closed one is removed.
//! A live session's frames of the last [`HISTORY_FRAMES`] are kept, so a
//! browser that joins late is given them first: its "last 10 s" starts
//! full, not from the moment it joined.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, SyncSender, TrySendError};
use std::sync::{Arc, Mutex};

/// Frames a browser may have waiting before new ones are dropped (about
/// 0.4 s at 20 frames per second).
pub(crate) const QUEUE_FRAMES: usize = 8;

/// The most browsers served at once.
pub(crate) const MAX_CLIENTS: usize = 8;

/// A live session's frames kept for a browser that joins late: 12 s at 20
/// frames per second (the page's longest live span is 10 s).
pub(crate) const HISTORY_FRAMES: usize = 240;

struct Client {
    tx: SyncSender<Arc<str>>,
    drops: Arc<AtomicU64>,
}

/// The browsers and the recent frames, under one lock: a browser joins
/// between two frames, so it gets each frame once — from the history or
/// from its queue.
#[derive(Default)]
struct Clients {
    list: Vec<Client>,
    history: VecDeque<Arc<str>>,
}

/// Every connected browser.
#[derive(Default)]
pub(crate) struct Hub {
    clients: Mutex<Clients>,
    /// Frames dropped over all browsers.
    pub drops: AtomicU64,
    /// Frames offered.
    pub frames: AtomicU64,
}

impl Hub {
    /// Adds a browser: the recent frames to send it first, its queue's
    /// receiving end and its drop counter; `None` when [`MAX_CLIENTS`] are
    /// connected.
    pub fn join(&self) -> Option<Joined> {
        let mut c = self.clients.lock().unwrap_or_else(|e| e.into_inner());
        if c.list.len() >= MAX_CLIENTS {
            return None;
        }
        let (tx, rx) = sync_channel(QUEUE_FRAMES);
        let drops = Arc::new(AtomicU64::new(0));
        c.list.push(Client { tx, drops: drops.clone() });
        Some(Joined { history: c.history.iter().cloned().collect(), rx, drops })
    }

    /// Offers a live session's `frame` to every browser without waiting,
    /// and keeps it for browsers that join later.
    pub fn broadcast_frame(&self, frame: Arc<str>) {
        let mut c = self.clients.lock().unwrap_or_else(|e| e.into_inner());
        if c.history.len() == HISTORY_FRAMES {
            c.history.pop_front();
        }
        c.history.push_back(frame.clone());
        self.offer(&mut c, frame);
    }

    /// Offers `frame` to every browser without waiting.
    pub fn broadcast(&self, frame: Arc<str>) {
        let mut c = self.clients.lock().unwrap_or_else(|e| e.into_inner());
        self.offer(&mut c, frame);
    }

    fn offer(&self, c: &mut Clients, frame: Arc<str>) {
        self.frames.fetch_add(1, Ordering::Relaxed);
        c.list.retain(|cl| match cl.tx.try_send(frame.clone()) {
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
        self.clients.lock().unwrap_or_else(|e| e.into_inner()).list.len()
    }

    /// Closes every queue (their connections end).
    pub fn close(&self) {
        self.clients.lock().unwrap_or_else(|e| e.into_inner()).list.clear();
    }
}

/// A browser that joined.
pub(crate) struct Joined {
    /// The live session's recent frames, oldest first, to send before the queue.
    pub history: Vec<Arc<str>>,
    /// Its queue of frames.
    pub rx: Receiver<Arc<str>>,
    /// Frames its full queue lost.
    pub drops: Arc<AtomicU64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_browser_that_does_not_read_loses_frames_and_never_blocks() {
        let hub = Hub::default();
        let Joined { rx, drops, .. } = hub.join().unwrap();
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
    fn a_late_browser_gets_the_recent_frames_once_each_and_no_results_twice() {
        let hub = Hub::default();
        for i in 0..HISTORY_FRAMES + 3 {
            hub.broadcast_frame(Arc::from(format!("{i}")));
        }
        hub.broadcast(Arc::from("result"));
        let j = hub.join().unwrap();
        let h: Vec<String> = j.history.iter().map(|f| f.to_string()).collect();
        assert_eq!(h.len(), HISTORY_FRAMES);
        assert_eq!((h[0].as_str(), h[HISTORY_FRAMES - 1].as_str()), ("3", &*format!("{}", HISTORY_FRAMES + 2)));
        hub.broadcast_frame(Arc::from("next"));
        assert_eq!(&*j.rx.recv().unwrap(), "next", "after the history, the queue: nothing twice, nothing missed");
        assert!(j.rx.try_recv().is_err());
    }

    #[test]
    fn at_most_max_clients() {
        let hub = Hub::default();
        let held: Vec<_> = (0..MAX_CLIENTS).map(|_| hub.join().unwrap()).collect();
        assert!(hub.join().is_none());
        drop(held);
    }
}
