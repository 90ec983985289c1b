//! Digests of query answers: a recording and a replay are compared
//! without storing the answers.
//!
//! Per query kind a [`Digest`] counts the queries and their hits and sums,
//! wrapping, a hash of (the query's position in its thread's log, its
//! kind, every field of its answer). The hash folds 64-bit words in one
//! at a time through MurmurHash3's 64-bit finalizer (`fmix64`, after
//! adding the golden-ratio constant), so a differing bit of an answer, or
//! an answer at another position, changes the sum except by a 64-bit
//! collision; the sum does not depend on the order in which the threads'
//! digests are added.

use super::record::Kind;
use lucent::accel::{Hit, ProbeHits};

/// Answers of one kind of query, summarized so that a recording and a
/// replay can be compared without storing the answers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Digest {
    pub queries: u64,
    /// Rays with a hit (nearest), occluded rays, or the sum of
    /// [`ProbeHits::total`] (probe).
    pub hits: u64,
    /// Wrapping sum over queries of a hash of (position in its thread's
    /// log, every field of the answer): any differing answer, or one at
    /// another position, changes it.
    pub hash: u64,
}

/// One [`Digest`] per [`Kind`], in [`Kind::ALL`] order.
pub type Digests = [Digest; 4];

fn mix(mut x: u64) -> u64 {
    x ^= x >> 33;
    x = x.wrapping_mul(0xff51_afd7_ed55_8ccd);
    x ^= x >> 33;
    x = x.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    x ^ (x >> 33)
}

fn chain(h: u64, v: u64) -> u64 {
    mix(h ^ v.wrapping_add(0x9e37_79b9_7f4a_7c15))
}

fn hash_hit(h: u64, hit: &Hit) -> u64 {
    let h = chain(h, (hit.geom as u64) << 32 | hit.prim as u64);
    let h = chain(h, hit.t.to_bits() as u64);
    chain(h, (hit.u.to_bits() as u64) << 32 | hit.v.to_bits() as u64)
}

/// One answer, as the recorder saw it or a replay got it.
pub(super) enum Answer<'a> {
    Nearest(Option<Hit>),
    Occluded(bool),
    Probe(&'a ProbeHits),
}

/// Adds the answer to the query at `position` of its thread's log.
pub(super) fn add_answer(d: &mut Digests, kind: Kind, position: usize, answer: &Answer) {
    let mut h = chain(position as u64, kind as u64);
    let hits = match answer {
        Answer::Nearest(hit) => {
            if let Some(hit) = hit {
                h = hash_hit(h, hit);
            }
            hit.is_some() as u64
        }
        Answer::Occluded(o) => {
            h = chain(h, *o as u64);
            *o as u64
        }
        Answer::Probe(p) => {
            h = chain(h, p.total() as u64);
            for hit in p.hits() {
                h = hash_hit(h, hit);
            }
            p.total() as u64
        }
    };
    let e = &mut d[kind.index()];
    e.queries += 1;
    e.hits += hits;
    e.hash = e.hash.wrapping_add(h);
}

/// Adds the digests `b` (another thread's) to `a`.
pub(super) fn sum_digests(a: &mut Digests, b: &Digests) {
    for (x, y) in a.iter_mut().zip(b) {
        x.queries += y.queries;
        x.hits += y.hits;
        x.hash = x.hash.wrapping_add(y.hash);
    }
}
