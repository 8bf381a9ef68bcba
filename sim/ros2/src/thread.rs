//! A [`BagWriter`] on its own thread: the caller hands each message over (a bounded queue of
//! [`QUEUE`] messages) and goes on; chunks are compressed and written there, beside the caller's
//! work, in whatever time the caller's threads leave (compressing a revolution's 1.5 MB cloud on
//! the loop's own thread put it on the loop's critical path).

use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

use crate::bag::{BagSummary, BagWriter, Qos, TopicId};
use crate::error::BagError;
use crate::msgs::MsgType;

/// Messages queued at most before `write` waits for the writer.
pub const QUEUE: usize = 256;

enum Command {
    Add(String, MsgType, Qos, TopicId),
    Write(TopicId, u64, Vec<u8>),
}

/// A bag written on its own thread.
pub struct BagThread {
    tx: Option<SyncSender<Command>>,
    handle: Option<JoinHandle<Result<BagSummary, BagError>>>,
    names: Vec<String>,
    file: std::path::PathBuf,
}

fn serve(mut bag: BagWriter, rx: &Receiver<Command>) -> Result<BagSummary, BagError> {
    while let Ok(command) = rx.recv() {
        match command {
            Command::Add(name, msg, qos, expected) => {
                let id = bag.add_topic(&name, msg, qos)?;
                debug_assert_eq!(id, expected);
            }
            Command::Write(topic, stamp_ns, cdr) => bag.write(topic, stamp_ns, &cdr)?,
        }
    }
    bag.finish()
}

impl BagThread {
    /// Moves `bag` to a thread of its own.
    ///
    /// # Errors
    /// The thread cannot be started.
    pub fn spawn(bag: BagWriter) -> Result<Self, BagError> {
        Self::spawn_with(bag, || {})
    }

    /// [`BagThread::spawn`], running `prepare` first on the new thread (to lower its priority:
    /// the caller knows its platform).
    ///
    /// # Errors
    /// The thread cannot be started.
    pub fn spawn_with(
        bag: BagWriter,
        prepare: impl FnOnce() + Send + 'static,
    ) -> Result<Self, BagError> {
        let names = bag.topic_names();
        let file = bag.file().to_path_buf();
        let (tx, rx) = sync_channel(QUEUE);
        let handle = std::thread::Builder::new()
            .name("bag writer".into())
            .spawn(move || {
                prepare();
                serve(bag, &rx)
            })
            .map_err(|source| BagError::Io {
                path: file.clone(),
                source,
            })?;
        Ok(Self {
            tx: Some(tx),
            handle: Some(handle),
            names,
            file,
        })
    }

    /// The error of a writer thread that panicked, its message kept.
    fn panicked(&self, panic: &(dyn std::any::Any + Send)) -> BagError {
        let text = panic
            .downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        BagError::Io {
            path: self.file.clone(),
            source: std::io::Error::other(format!("the bag writer panicked: {text}")),
        }
    }

    /// The writer's error, once its thread has stopped (a send failed).
    fn stopped(&mut self) -> BagError {
        self.tx = None;
        match self.handle.take().map(JoinHandle::join) {
            Some(Ok(Err(e))) => e,
            Some(Err(panic)) => self.panicked(panic.as_ref()),
            Some(Ok(Ok(_))) | None => BagError::Io {
                path: self.file.clone(),
                source: std::io::Error::other("the bag writer had already stopped"),
            },
        }
    }

    fn send(&mut self, command: Command) -> Result<(), BagError> {
        let Some(tx) = &self.tx else {
            return Err(self.stopped());
        };
        if tx.send(command).is_err() {
            return Err(self.stopped());
        }
        Ok(())
    }

    /// Adds a topic, as [`BagWriter::add_topic`].
    ///
    /// # Errors
    /// The topic is there already, or the writer has stopped on an error (given here).
    pub fn add_topic(&mut self, name: &str, msg: MsgType, qos: Qos) -> Result<TopicId, BagError> {
        if self.names.iter().any(|n| n == name) {
            return Err(BagError::Topic {
                path: self.file.clone(),
                topic: name.to_string(),
                what: "added twice".to_string(),
            });
        }
        let id = TopicId::nth(self.names.len());
        self.names.push(name.to_string());
        self.send(Command::Add(name.to_string(), msg, qos, id))?;
        Ok(id)
    }

    /// Hands one message over; waits only when [`QUEUE`] are waiting already.
    ///
    /// # Errors
    /// The writer has stopped on an error (given here).
    pub fn write(&mut self, topic: TopicId, stamp_ns: u64, cdr: Vec<u8>) -> Result<(), BagError> {
        self.send(Command::Write(topic, stamp_ns, cdr))
    }

    /// Waits for every message to be written, then finishes the bag.
    ///
    /// # Errors
    /// As [`BagWriter::finish`], or an error the writer stopped on.
    pub fn finish(mut self) -> Result<BagSummary, BagError> {
        self.tx = None;
        match self.handle.take().map(JoinHandle::join) {
            Some(Ok(result)) => result,
            Some(Err(panic)) => Err(self.panicked(panic.as_ref())),
            None => Err(self.stopped()),
        }
    }
}

impl Drop for BagThread {
    /// A bag dropped unfinished (the run failed) is still closed and renamed into place: what
    /// was handed over is written.
    fn drop(&mut self) {
        self.tx = None;
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msgs;

    /// The same messages through the thread make the same bag as written directly.
    #[test]
    fn a_bag_written_on_a_thread_is_the_same_bag() {
        let dir = tempfile::tempdir().unwrap();
        let write = |name: &str, threaded: bool| {
            let sub = dir.path().join(name);
            std::fs::create_dir_all(&sub).unwrap();
            let file = sub.join("b.mcap");
            let bag = BagWriter::create(&file).unwrap();
            let messages: Vec<(u64, Vec<u8>)> = (0..500u64)
                .map(|k| (k * 1000, msgs::clock(msgs::Time::from_ns(k * 1000))))
                .collect();
            let summary = if threaded {
                let mut bag = BagThread::spawn(bag).unwrap();
                let clock = bag.add_topic("/clock", msgs::CLOCK, Qos::Stream).unwrap();
                assert!(bag.add_topic("/clock", msgs::CLOCK, Qos::Stream).is_err());
                for (t, m) in messages {
                    bag.write(clock, t, m).unwrap();
                }
                bag.finish().unwrap()
            } else {
                let mut bag = bag;
                let clock = bag.add_topic("/clock", msgs::CLOCK, Qos::Stream).unwrap();
                for (t, m) in messages {
                    bag.write(clock, t, &m).unwrap();
                }
                bag.finish().unwrap()
            };
            (summary.topics, std::fs::read(&file).unwrap())
        };
        let (a, b) = (write("direct", false), write("thread", true));
        assert_eq!(a.0, [("/clock".to_string(), 500)]);
        assert_eq!(a, b);
    }
}
