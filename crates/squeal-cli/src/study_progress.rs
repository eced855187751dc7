//! The progress display of the zone studies (`squeal sweep macro|meso`): finished cases,
//! rate and time left.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use squeal_analysis::study::Progress;
use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::Instant;

/// The progress display: an indicatif bar on a terminal, one line per case otherwise
/// (hidden bar when stderr is not a terminal or `CI=true`).
pub struct Bar {
    bar: ProgressBar,
    visible: bool,
    state: Mutex<(usize, usize, Instant)>,
}

impl Bar {
    pub fn new() -> Self {
        let ci = std::env::var("CI").is_ok_and(|v| v == "true" || v == "1");
        let visible = std::io::stderr().is_terminal() && !ci;
        let bar = ProgressBar::new(0);
        if visible {
            bar.set_style(
                ProgressStyle::with_template(
                    "{bar:30} {pos}/{len} cases  {per_sec}  ETA {eta}  {msg}",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
        } else {
            bar.set_draw_target(ProgressDrawTarget::hidden());
        }
        Self {
            bar,
            visible,
            state: Mutex::new((0, 0, Instant::now())),
        }
    }

    pub fn update(&self, p: Progress<'_>) {
        let mut st = self.state.lock().unwrap_or_else(|e| e.into_inner());
        match p {
            Progress::Start {
                resumed,
                todo,
                shard,
            } => {
                *st = (resumed, todo, Instant::now());
                self.bar.set_length(todo as u64);
                self.bar.reset_eta();
                if resumed > 0 {
                    eprintln!("resuming: {resumed} of {shard} cases already done, {todo} to run");
                }
            }
            Progress::Case { done, record } => {
                let unstable: Vec<String> = record
                    .unstable
                    .iter()
                    .map(|m| format!("{:.0} Hz DvR {:.4}", m.freq_hz, m.dvr))
                    .collect();
                let what = match &record.error {
                    Some(e) => format!("FAILED: {e}"),
                    None if unstable.is_empty() => "stable".into(),
                    None => unstable.join(", "),
                };
                if self.visible {
                    self.bar.set_position(done as u64);
                    self.bar.set_message(format!("{}: {what}", record.case.id));
                } else {
                    let (_, todo, t0) = *st;
                    let el = t0.elapsed().as_secs_f64();
                    let rate = done as f64 / el.max(1e-9);
                    let eta = (todo - done.min(todo)) as f64 / rate.max(1e-12);
                    eprintln!(
                        "[{done}/{todo}] {} ({} pairs): {what}  ({:.2} cases/min, ETA {})",
                        record.case.id,
                        record.case.pairs,
                        rate * 60.0,
                        hms(eta)
                    );
                }
            }
        }
    }

    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

fn hms(s: f64) -> String {
    let s = s.round() as u64;
    format!("{}:{:02}:{:02}", s / 3600, (s / 60) % 60, s % 60)
}
