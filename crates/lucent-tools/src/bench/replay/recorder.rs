//! Recording a render's ray queries: [`Recorder`] is an [`Accel`] that
//! forwards every query to the real backend and appends it, as a
//! [`Record`], to the log of the rayon worker that issued it, in issue
//! order, with a [`Digest`](super::Digest) of every answer; a recorder
//! logs at most its cap and counts the rest as dropped.

use std::sync::Mutex;

use super::digest::{add_answer, sum_digests, Answer, Digests};
use super::record::{Kind, Record};
use lucent::accel::{Accel, Hit, ProbeHits};
use lucent::geometry::{Ray, Vec3};

#[derive(Default)]
struct Slot {
    log: Vec<Record>,
    digests: Digests,
    /// Queries not logged because the slot was full.
    dropped: u64,
}

/// An [`Accel`] that forwards to `inner` and logs every query per rayon
/// worker, in the order each worker issued them.
///
/// Workers are told apart by `rayon::current_thread_index()`, so the
/// recorder must be used from one pool of `threads` workers (as
/// [`lucent::render::render`] does); a query from outside any pool goes to slot 0.
/// Each slot is a mutex only its own worker locks, so the locks are
/// uncontended.
pub struct Recorder<'a> {
    inner: &'a dyn Accel,
    eye: Vec3,
    slots: Vec<Mutex<Slot>>,
    cap_per_slot: usize,
}

impl<'a> Recorder<'a> {
    /// `eye`: the camera position, which tells primary rays from others.
    /// At most `max_records` queries are logged in all (spread evenly
    /// over the workers); beyond that they are counted as dropped.
    pub fn new(inner: &'a dyn Accel, eye: Vec3, threads: usize, max_records: usize) -> Self {
        let threads = threads.max(1);
        Recorder {
            inner,
            eye,
            slots: (0..threads).map(|_| Mutex::default()).collect(),
            cap_per_slot: max_records / threads,
        }
    }

    fn log(&self, rec: Record, answer: Answer) {
        let i = rayon::current_thread_index().unwrap_or(0);
        let mut slot = self.slots[i.min(self.slots.len() - 1)]
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        if slot.log.len() >= self.cap_per_slot {
            slot.dropped += 1;
            return;
        }
        let position = slot.log.len();
        slot.log.push(rec);
        add_answer(&mut slot.digests, rec.kind, position, &answer);
    }

    /// The per-worker logs, the digest of the answers the recorded
    /// queries got, and how many queries were not logged (over the cap).
    pub fn finish(self) -> (Vec<Vec<Record>>, Digests, u64) {
        let mut digests = Digests::default();
        let mut dropped = 0;
        let logs = self
            .slots
            .into_iter()
            .map(|m| {
                let s = m.into_inner().unwrap_or_else(|e| e.into_inner());
                sum_digests(&mut digests, &s.digests);
                dropped += s.dropped;
                s.log
            })
            .collect();
        (logs, digests, dropped)
    }
}

impl Accel for Recorder<'_> {
    fn name(&self) -> &'static str {
        self.inner.name()
    }

    fn intersect(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        let hit = self.inner.intersect(ray, tmin, tmax);
        let kind = if ray.o == self.eye {
            Kind::Camera
        } else {
            Kind::Nearest
        };
        let rec = Record {
            ray: *ray,
            tmin,
            tmax,
            geom: 0,
            seed: 0,
            kind,
        };
        self.log(rec, Answer::Nearest(hit));
        hit
    }

    fn occluded(&self, ray: &Ray, tmin: f32, tmax: f32) -> bool {
        let o = self.inner.occluded(ray, tmin, tmax);
        let rec = Record {
            ray: *ray,
            tmin,
            tmax,
            geom: 0,
            seed: 0,
            kind: Kind::Occluded,
        };
        self.log(rec, Answer::Occluded(o));
        o
    }

    fn hits_on_segment(&self, ray: &Ray, tmax: f32, geom: u32, seed: u32, out: &mut ProbeHits) {
        self.inner.hits_on_segment(ray, tmax, geom, seed, out);
        let rec = Record {
            ray: *ray,
            tmin: 0.0,
            tmax,
            geom,
            seed,
            kind: Kind::Probe,
        };
        self.log(rec, Answer::Probe(out));
    }

    fn rejected_rays(&self) -> u64 {
        self.inner.rejected_rays()
    }
}
