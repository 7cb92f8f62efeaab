//! A fuzzing session: cases in order from a seed until a case count or a
//! time is reached, with the tally the closing report gives.

use std::collections::BTreeMap;
use std::path::Path;
use std::time::{Duration, Instant};

use super::{Limits, Report, Verdict, generate, run_case};

/// When a session stops.
#[derive(Clone, Copy, Debug)]
pub struct Stop {
    /// At most this many cases.
    pub cases: Option<u64>,
    /// At most this long (a case under way is finished).
    pub time: Option<Duration>,
    /// Pass over the cases that try known faults owned elsewhere
    /// (`Case::open`): a bounded run in CI spends no minutes on them.
    pub skip_open: bool,
}

/// What a session did.
#[derive(Debug, Default)]
pub struct Tally {
    /// Cases run.
    pub cases: u64,
    /// Cases per verdict.
    pub verdicts: BTreeMap<Verdict, u64>,
    /// Each faulty case: its index, the case and the report.
    pub faults: Vec<(u64, super::Case, Report)>,
    /// Faulty cases of known faults owned elsewhere (`Case::open`).
    pub open: Vec<(u64, super::Case, Report)>,
    /// Cases passed over (`Stop::skip_open`).
    pub skipped: u64,
    /// Wall time.
    pub seconds: f64,
}

impl Tally {
    /// Cases with `v`.
    pub fn count(&self, v: Verdict) -> u64 {
        self.verdicts.get(&v).copied().unwrap_or(0)
    }

    /// One line: cases, each fault class (zeros too), length.
    pub fn summary(&self) -> String {
        let c = |v| self.count(v);
        format!(
            "{} cases in {:.0} s: {} clean, {} panics, {} signals, {} timeouts, {} wrong successes, \
             {} wrong failures, {} partial outputs, {} odd exits ({} of the faulty cases try faults \
             known and owned by other parts of issue 39; {} such cases passed over)",
            self.cases,
            self.seconds,
            c(Verdict::Clean),
            c(Verdict::Panic),
            c(Verdict::Signal),
            c(Verdict::Timeout),
            c(Verdict::WrongSuccess),
            c(Verdict::WrongFailure),
            c(Verdict::PartialOutput),
            c(Verdict::OddExit),
            self.open.len(),
            self.skipped
        )
    }
}

/// Run cases `seed`/0, 1, 2, ... until `stop`; `each` sees every report.
pub fn run(
    bin: &Path,
    seed: u64,
    stop: Stop,
    limits: Limits,
    scratch: &Path,
    mut each: impl FnMut(u64, &super::Case, &Report),
) -> std::io::Result<Tally> {
    let start = Instant::now();
    let mut t = Tally::default();
    for index in 0.. {
        if stop.cases.is_some_and(|n| index >= n) || stop.time.is_some_and(|d| start.elapsed() >= d)
        {
            break;
        }
        let case = generate::case(seed, index);
        if stop.skip_open && case.open.is_some() {
            t.skipped += 1;
            continue;
        }
        let r = run_case(bin, &case, limits, scratch)?;
        each(index, &case, &r);
        *t.verdicts.entry(r.verdict.clone()).or_default() += 1;
        t.cases += 1;
        if r.verdict != Verdict::Clean {
            if case.open.is_some() {
                t.open.push((index, case, r));
            } else {
                t.faults.push((index, case, r));
            }
        }
    }
    t.seconds = start.elapsed().as_secs_f64();
    Ok(t)
}
