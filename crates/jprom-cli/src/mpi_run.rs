//! `mpirun -np N jprom run STUDY` (cargo feature `mpi`, off by default): a study's units
//! ([`crate::units`]) dealt to MPI ranks.
//!
//! - Rank 0 builds the shared inputs once ([`build_shared`]: each parameter case's model on the
//!   one Craig-Bampton reduction, and its level reference) and broadcasts them (MessagePack, `MPI_Bcast`); the other ranks wait for
//!   them in a non-blocking barrier polled every 10 ms, so that they leave the cores to rank 0's
//!   Craig-Bampton instead of spinning in MPI.
//! - Rank 0 deals the units dynamically: a rank that finishes sends its unit's output with its
//!   request for the next, and gets the next unit in study order whose level's full-order unit is
//!   done ([`Dealer`], with that unit's peak). Rank 0 runs units too, in a second thread; only
//!   its main thread calls MPI (`MPI_THREAD_FUNNELED`).
//! - Rank 0 merges the outputs in unit order and writes the CSVs, `summary.json` and the plots
//!   ([`merge_units`]): the same files as a serial run. A unit that fails on any rank (an error
//!   or a panic) comes back as its failed row; a rank that dies ends the job through `mpirun`.
//!   No rank waits for a message that cannot come.
//!
//! With one rank it is the serial run (`jprom run --jobs N` still takes threads).

use crate::progress::Progress;
use crate::run::{build_shared, merge_units, FoPeak, RunSummary, Shared, UnitOutput, UnitRunner};
use crate::study::Study;
use crate::units::{run_unit, study_units, Dealer, Next};
use jprom::error::{JpError, Result};
use mpi::point_to_point::MatchedReceiveVec;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;
use std::path::Path;
use std::time::Duration;

/// Worker to rank 0: the output of its last unit (none at first) and a request for the next.
const TAG_ASK: i32 = 16;
/// Rank 0 to a worker: a unit to run, or stop.
const TAG_DEAL: i32 = 17;
/// How long an idle rank sleeps between two looks for a message.
const POLL: Duration = Duration::from_millis(10);

#[derive(Serialize, Deserialize)]
enum Ask {
    First,
    Done(usize, UnitOutput),
}

#[derive(Serialize, Deserialize)]
enum Deal {
    Run(usize, Option<FoPeak>),
    Stop,
}

/// MPI, initialised for the whole run (finalised when dropped).
pub struct Mpi {
    _universe: mpi::environment::Universe,
    world: SimpleCommunicator,
}

impl Mpi {
    /// Initialises MPI (`MPI_THREAD_FUNNELED`: rank 0 runs units in a second thread, which never
    /// calls MPI); `None` if MPI was already initialised or gives less than that.
    pub fn init() -> Option<Mpi> {
        let (universe, level) = mpi::initialize_with_threading(mpi::Threading::Funneled)?;
        if level == mpi::Threading::Single {
            return None;
        }
        let world = universe.world();
        Some(Mpi { _universe: universe, world })
    }

    pub fn rank(&self) -> usize {
        self.world.rank() as usize
    }

    pub fn size(&self) -> usize {
        self.world.size() as usize
    }
}

fn encode<T: Serialize>(x: &T) -> Vec<u8> {
    rmp_serde::to_vec_named(x).expect("MessagePack encoding of plain data")
}

fn decode<T: for<'de> Deserialize<'de>>(bytes: &[u8], what: &str) -> Result<T> {
    rmp_serde::from_slice(bytes).map_err(|e| JpError::invalid("mpi", format!("cannot decode {what}: {e}")))
}

/// Waits (sleeping, not spinning) for the next message with `tag` from `source` (any rank if
/// `None`): its bytes and its sender.
fn receive(world: &SimpleCommunicator, source: Option<usize>, tag: i32) -> (Vec<u8>, usize) {
    loop {
        let probe = match source {
            Some(r) => world.process_at_rank(r as i32).immediate_matched_probe_with_tag(tag),
            None => world.any_process().immediate_matched_probe_with_tag(tag),
        };
        if let Some(m) = probe {
            let (bytes, status) = m.matched_receive_vec::<u8>();
            return (bytes, status.source_rank() as usize);
        }
        std::thread::sleep(POLL);
    }
}

/// Rank 0's shared inputs (`bytes`, rank 0 only) to every rank: an idle wait in a
/// non-blocking barrier, then the length and the bytes by `MPI_Bcast`.
fn broadcast(world: &SimpleCommunicator, bytes: Option<Vec<u8>>) -> Vec<u8> {
    let mut barrier = world.immediate_barrier();
    loop {
        match barrier.test() {
            Ok(_) => break,
            Err(pending) => barrier = pending,
        }
        std::thread::sleep(POLL);
    }
    let root = world.process_at_rank(0);
    let mut bytes = bytes.unwrap_or_default();
    let mut len = bytes.len() as u64;
    root.broadcast_into(&mut len);
    bytes.resize(len as usize, 0);
    root.broadcast_into(&mut bytes[..]);
    bytes
}

/// Runs `study` on every rank of `mpi`: on rank 0 the summary (files written into `out_dir`),
/// on the others `None`. With one rank, the serial run in `jobs` threads.
///
/// # Errors
/// On rank 0: the model's errors, a file that cannot be written (the other ranks then return
/// `None`). A unit that fails is a row of the summary.
pub fn run_study_mpi(mpi: &Mpi, study: &Study, out_dir: &Path, progress: Progress, jobs: usize) -> Result<Option<RunSummary>> {
    let world = &mpi.world;
    if mpi.size() == 1 {
        return crate::run::run_study_jobs(study, out_dir, progress, jobs).map(Some);
    }
    let units = study_units(study);
    if mpi.rank() != 0 {
        let bytes = broadcast(world, None);
        // rank 0 failed to build the model: it says why
        if let Ok(Ok(shared)) = decode::<std::result::Result<Shared, String>>(&bytes, "the shared model") {
            worker(world, study, &shared, &units);
        }
        return Ok(None);
    }
    std::fs::create_dir_all(out_dir).map_err(|e| JpError::Io { path: out_dir.display().to_string(), reason: e.to_string() })?;
    let built = build_shared(&crate::run::writing_to(study, out_dir), progress).and_then(|s| {
        UnitRunner::new(study, &s, progress)?;
        Ok(s)
    });
    let step = progress.step(format!("sending the shared model to {} ranks", mpi.size() - 1));
    let bytes = encode(&built.as_ref().map_err(|e| e.to_string()));
    let n_bytes = bytes.len();
    broadcast(world, Some(bytes));
    step.done_with(&format!(", {:.1} MB", n_bytes as f64 / 1e6));
    let shared = built?;
    // concurrent units print plain lines (bars of several threads would overwrite each other)
    let unit_progress = if progress == Progress::Bars { Progress::Lines } else { progress };
    let runner = UnitRunner::new(study, &shared, unit_progress)?;
    let outputs = deal(world, mpi.size(), &runner, &units, progress);
    let (units, outputs) = crate::fall_back::with_fall_backs(&runner, study.solvers.fall_back, units, outputs, jobs);
    merge_units(study, out_dir, &shared, &units, outputs).map(Some)
}

/// Who runs units: rank 0's unit thread, or another rank.
#[derive(Clone, Copy)]
enum Worker {
    Local,
    Remote(usize),
}

/// Rank 0: deals `units` to its own unit thread and to ranks `1..size` as each becomes free,
/// until every one has been told to stop; the outputs in unit order.
fn deal(world: &SimpleCommunicator, size: usize, runner: &UnitRunner, units: &[crate::units::Unit], progress: Progress) -> Vec<UnitOutput> {
    use std::sync::mpsc::{channel, TryRecvError};
    let mut dealer = Dealer::new(units);
    let (to_local, local_deals) = channel::<Deal>();
    let (local_done, from_local) = channel::<(usize, UnitOutput)>();
    std::thread::scope(|s| {
        std::thread::Builder::new()
            .name("jprom-unit-rank0".into())
            .stack_size(8 << 20)
            .spawn_scoped(s, move || {
                while let Ok(Deal::Run(i, fo)) = local_deals.recv() {
                    if local_done.send((i, run_unit(runner, units, i, fo.as_ref(), Some(0)))).is_err() {
                        break;
                    }
                }
            })
            .expect("rank 0's unit thread");
        let mut idle: VecDeque<Worker> = VecDeque::from([Worker::Local]);
        // the unit each rank runs (rank 0: its unit thread)
        let mut running: Vec<Option<usize>> = vec![None; size];
        let mut stopped = 0;
        while stopped < size {
            let mut busy = false;
            loop {
                match from_local.try_recv() {
                    Ok((i, out)) => {
                        dealer.done(i, out);
                        running[0] = None;
                        idle.push_back(Worker::Local);
                        busy = true;
                    }
                    Err(TryRecvError::Disconnected) if running[0].is_some() => {
                        let i = running[0].take().expect("a unit");
                        dealer.done(i, UnitOutput::failed(&units[i], i, "rank 0's unit thread ended"));
                        stopped += 1;
                        busy = true;
                    }
                    Err(_) => break,
                }
            }
            while let Some(m) = world.any_process().immediate_matched_probe_with_tag(TAG_ASK) {
                let (bytes, status) = m.matched_receive_vec::<u8>();
                let r = status.source_rank() as usize;
                match decode::<Ask>(&bytes, "a unit's output") {
                    Ok(Ask::First) => {}
                    Ok(Ask::Done(i, out)) => {
                        if progress != Progress::Quiet {
                            eprintln!("jprom: unit {i} ({}) done on rank {r}", units[i].describe());
                        }
                        dealer.done(i, out);
                    }
                    Err(e) => {
                        if let Some(i) = running[r] {
                            dealer.done(i, UnitOutput::failed(&units[i], i, &format!("rank {r}: {e}")));
                        }
                    }
                }
                running[r] = None;
                idle.push_back(Worker::Remote(r));
                busy = true;
            }
            while let Some(w) = idle.pop_front() {
                let deal = match dealer.next() {
                    Next::Run(i, fo) => Deal::Run(i, fo),
                    Next::Wait => {
                        idle.push_front(w);
                        break;
                    }
                    Next::Finished => Deal::Stop,
                };
                let rank = match w {
                    Worker::Local => 0,
                    Worker::Remote(r) => r,
                };
                match &deal {
                    Deal::Run(i, _) => running[rank] = Some(*i),
                    Deal::Stop => stopped += 1,
                }
                match w {
                    Worker::Local => {
                        let _ = to_local.send(deal);
                    }
                    Worker::Remote(r) => world.process_at_rank(r as i32).send_with_tag(&encode(&deal)[..], TAG_DEAL),
                }
                busy = true;
            }
            if !busy {
                std::thread::sleep(Duration::from_millis(2));
            }
        }
    });
    dealer.into_outputs()
}

/// Ranks `1..`: asks rank 0 for a unit, runs it, sends its output with the next request, until
/// told to stop.
fn worker(world: &SimpleCommunicator, study: &Study, shared: &Shared, units: &[crate::units::Unit]) {
    let runner = UnitRunner::new(study, shared, Progress::Quiet);
    let root = world.process_at_rank(0);
    let mut ask = Ask::First;
    loop {
        root.send_with_tag(&encode(&ask)[..], TAG_ASK);
        let (bytes, _) = receive(world, Some(0), TAG_DEAL);
        match decode::<Deal>(&bytes, "a unit from rank 0") {
            Ok(Deal::Run(i, fo)) => {
                let out = match &runner {
                    Ok(r) => run_unit(r, units, i, fo.as_ref(), Some(world.rank() as usize)),
                    Err(e) => UnitOutput::failed(&units[i], i, &format!("rank {}: {e}", world.rank())),
                };
                ask = Ask::Done(i, out);
            }
            Ok(Deal::Stop) => return,
            Err(e) => {
                // rank 0 would wait for this rank's answer: end the job instead
                eprintln!("jprom (rank {}): {e}", world.rank());
                world.abort(1);
            }
        }
    }
}
