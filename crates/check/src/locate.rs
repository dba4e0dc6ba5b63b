//! Finding PSD4xx process data in cyclic PROFINET frames (bus description 3.5): from the
//! capture's own Connect (expected submodules with the output and input module lengths of
//! the spec, or a module ident), from options (frame IDs and offsets), or by a search over
//! the first cyclic frames for windows that behave like PSD4xx process data.
//!
//! The search looks at every offset of every cyclic stream. A window qualifies as output
//! (input) when every frame holds a PKW command (response) code of the spec's tables with
//! SPM clear, no reserved control bit, and some activity; output and input windows are then
//! paired across the two directions between the same stations and scored by behaviour: a
//! PKW command answered for the same parameter, control bit 13 echoed in status bit 2, a run
//! with the release set. Confidence is 0.5 plus 0.25, 0.15 and 0.1 for these; at least one
//! is required (0.6). Memory and time are bounded: the frames are the caller's bounded
//! buffer; at most 64 streams are searched, candidate windows are tested on 256 frames per
//! stream and capped per stream, and at most 256 pairs per pair of streams and 4096 in all
//! are scored. Nothing here panics.

use drivespec_psd4xx::{Input, Output, Rules};

/// Most candidate windows kept per stream and direction.
const MAX_CANDIDATES: usize = 64;

/// Most streams searched.
const MAX_STREAMS: usize = 64;

/// Frames per stream a candidate window is tested on.
const FRAMES_PER_STREAM: usize = 256;

/// Most output/input window pairs scored (each costs one pass over their frames).
const MAX_PAIRS: usize = 4096;

/// Most window pairs scored per pair of streams.
const MAX_PAIRS_PER_STREAMS: usize = 256;

/// A cyclic stream: FrameID, source and destination MAC (zeros when unknown).
pub type StreamKey = (u16, [u8; 6], [u8; 6]);

/// Where one direction of a drive's process data is (bus description 3.5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Binding {
    /// FrameID of the frames carrying it.
    pub frame_id: u16,
    /// Source MAC of those frames, when known.
    pub src: Option<[u8; 6]>,
    /// Offset of the module in the C_SDU.
    pub offset: usize,
    /// Offset of the provider status (IOPS) after the data, when known (Connect).
    pub iops: Option<usize>,
}

impl Binding {
    /// Whether a frame of `key` carries this binding.
    pub fn matches(&self, key: &StreamKey) -> bool {
        key.0 == self.frame_id && self.src.is_none_or(|s| s == key.1)
    }
}

/// A buffered cyclic frame for the search.
#[derive(Debug, Clone)]
pub struct Buffered {
    /// Its stream.
    pub key: StreamKey,
    /// C_SDU and padding.
    pub data: Vec<u8>,
    /// Where it is in the capture.
    pub at: crate::report::Where,
    /// Whether its provider was in RUN with valid data (DataStatus).
    pub valid: bool,
}

/// A PSD4xx found by the search.
#[derive(Debug, Clone, PartialEq)]
pub struct Found {
    /// Output module (controller → drive).
    pub out: Binding,
    /// Input module (drive → controller).
    pub inp: Binding,
    /// 0.6 to 1.
    pub confidence: f64,
    /// What behaved like a PSD4xx.
    pub evidence: Vec<String>,
}

fn output_ok(rules: &Rules, w: &[u8]) -> bool {
    let Ok(o) = Output::parse(rules, w) else {
        return false;
    };
    let mbz = rules.control_bits().must_be_zero_mask() as u16;
    rules.pkw().commands().contains(o.pkw.ak) && !o.pkw.spm && o.control & mbz == 0
}

fn input_ok(rules: &Rules, w: &[u8]) -> bool {
    let Ok(i) = Input::parse(rules, w) else {
        return false;
    };
    let pkw = rules.pkw();
    let known = i.pkw.ak == pkw.response_codes().no_response
        || i.pkw.ak == pkw.response_codes().cannot_execute
        || rules.parameter(u32::from(i.pkw.pnu)).is_some();
    pkw.responses().contains(i.pkw.ak) && !i.pkw.spm && known
}

/// Windows of `len` bytes in every frame of `frames` (one stream) that pass `ok`.
fn candidates(
    rules: &Rules,
    frames: &[&Buffered],
    len: usize,
    ok: fn(&Rules, &[u8]) -> bool,
) -> Vec<usize> {
    let min_len = frames.iter().map(|f| f.data.len()).min().unwrap_or(0);
    let mut out = Vec::new();
    for offset in 0..=min_len.saturating_sub(len) {
        if min_len < len {
            break;
        }
        let mut active = false;
        let mut first: Option<&[u8]> = None;
        let all = frames.iter().all(|f| {
            let Some(w) = f.data.get(offset..offset + len) else {
                return false;
            };
            match first {
                None => first = Some(w),
                Some(x) if x != w => active = true,
                Some(_) => {}
            }
            ok(rules, w)
        });
        let nonzero = first.is_some_and(|w| w.iter().any(|b| *b != 0));
        if all && (active || nonzero) {
            out.push(offset);
            if out.len() >= MAX_CANDIDATES {
                break;
            }
        }
    }
    out
}

/// How a pair of windows behaves (see the module docs).
fn score(
    rules: &Rules,
    frames: &[&Buffered],
    out: (StreamKey, usize),
    inp: (StreamKey, usize),
) -> (f64, Vec<String>) {
    let olen = Output::buffer_len(rules);
    let ilen = Input::buffer_len(rules);
    let pkw = rules.pkw();
    let mut last_out: Option<Output> = None;
    let mut pending_pnu: Option<u16> = None;
    let mut pkw_match = 0u32;
    let mut toggle_changes = 0u32;
    let mut echoes = 0u32;
    let mut pending_toggle: Option<bool> = None;
    let mut motion = false;
    for f in frames {
        if f.key == out.0 {
            let Some(o) = f
                .data
                .get(out.1..out.1 + olen)
                .and_then(|w| Output::parse(rules, w).ok())
            else {
                continue;
            };
            if o.pkw.ak != pkw.command_codes().no_command
                && rules.parameter(u32::from(o.pkw.pnu)).is_some()
            {
                pending_pnu = Some(o.pkw.pnu);
            }
            if let Some(prev) = last_out {
                if (prev.control ^ o.control) & (1 << 13) != 0 {
                    toggle_changes += 1;
                    pending_toggle = Some(o.control & (1 << 13) != 0);
                }
            }
            last_out = Some(o);
        } else if f.key == inp.0 {
            let Some(i) = f
                .data
                .get(inp.1..inp.1 + ilen)
                .and_then(|w| Input::parse(rules, w).ok())
            else {
                continue;
            };
            if let Some(p) = pending_pnu {
                if i.pkw.ak != pkw.response_codes().no_response && i.pkw.pnu == p {
                    pkw_match += 1;
                    pending_pnu = None;
                }
            }
            if let Some(t) = pending_toggle {
                if (i.status & (1 << 2) != 0) == t {
                    echoes += 1;
                    pending_toggle = None;
                }
            }
            let release = last_out.is_some_and(|o| o.control & (1 << 4) != 0);
            if release && i.speed != 0 && i.status & (1 << 6) != 0 {
                motion = true;
            }
        }
    }
    let mut confidence = 0.5;
    let mut evidence = Vec::new();
    if pkw_match > 0 {
        confidence += 0.25;
        evidence.push(format!(
            "{pkw_match} PKW command(s) answered for the same parameter"
        ));
    }
    if toggle_changes > 0 && echoes == toggle_changes {
        confidence += 0.15;
        evidence.push(format!(
            "control bit 13 echoed in status bit 2 {echoes} time(s)"
        ));
    }
    if motion {
        confidence += 0.1;
        evidence.push("speed and running bit while the release is set".into());
    }
    (confidence, evidence)
}

/// Searches `frames` (a bounded buffer of the first cyclic frames) for PSD4xx windows.
pub fn search(rules: &Rules, frames: &[Buffered]) -> Vec<Found> {
    let mut keys: Vec<StreamKey> = Vec::new();
    for f in frames {
        if !keys.contains(&f.key) {
            keys.push(f.key);
        }
        if keys.len() >= MAX_STREAMS {
            break;
        }
    }
    let olen = Output::buffer_len(rules);
    let ilen = Input::buffer_len(rules);
    let mut outs = Vec::new();
    let mut ins = Vec::new();
    for k in &keys {
        let of: Vec<&Buffered> = frames
            .iter()
            .filter(|f| f.key == *k)
            .take(FRAMES_PER_STREAM)
            .collect();
        if of.len() < 2 {
            continue;
        }
        for o in candidates(rules, &of, olen, output_ok) {
            outs.push((*k, o));
        }
        for i in candidates(rules, &of, ilen, input_ok) {
            ins.push((*k, i));
        }
    }
    let mut pairs = Vec::new();
    let mut scored = 0usize;
    let mut per_streams: Vec<((StreamKey, StreamKey), usize)> = Vec::new();
    'outer: for o in &outs {
        for i in &ins {
            let reverse = o.0 .1 == i.0 .2 && o.0 .2 == i.0 .1;
            let unknown = o.0 .1 == [0; 6] || i.0 .1 == [0; 6];
            if o.0 == i.0 || !(reverse || unknown) {
                continue;
            }
            if scored >= MAX_PAIRS {
                break 'outer;
            }
            let n = match per_streams.iter_mut().find(|(k, _)| *k == (o.0, i.0)) {
                Some((_, n)) => n,
                None => {
                    per_streams.push(((o.0, i.0), 0));
                    match per_streams.last_mut() {
                        Some((_, n)) => n,
                        None => continue,
                    }
                }
            };
            if *n >= MAX_PAIRS_PER_STREAMS {
                continue;
            }
            *n += 1;
            scored += 1;
            let both: Vec<&Buffered> = frames
                .iter()
                .filter(|f| f.key == o.0 || f.key == i.0)
                .collect();
            let (c, ev) = score(rules, &both, *o, *i);
            if c >= 0.6 {
                pairs.push((c, *o, *i, ev));
            }
        }
    }
    pairs.sort_by(|a, b| {
        b.0.partial_cmp(&a.0)
            .unwrap_or(std::cmp::Ordering::Equal)
            .then(a.1 .1.cmp(&b.1 .1))
            .then(a.2 .1.cmp(&b.2 .1))
    });
    let mut used: Vec<(StreamKey, usize, usize)> = Vec::new();
    let overlaps = |used: &[(StreamKey, usize, usize)], k: StreamKey, o: usize, len: usize| {
        used.iter()
            .any(|(uk, uo, ul)| *uk == k && o < uo + ul && *uo < o + len)
    };
    let mut found = Vec::new();
    for (c, o, i, ev) in pairs {
        if overlaps(&used, o.0, o.1, olen) || overlaps(&used, i.0, i.1, ilen) {
            continue;
        }
        used.push((o.0, o.1, olen));
        used.push((i.0, i.1, ilen));
        let src = |k: StreamKey| (k.1 != [0; 6]).then_some(k.1);
        found.push(Found {
            out: Binding {
                frame_id: o.0 .0,
                src: src(o.0),
                offset: o.1,
                iops: None,
            },
            inp: Binding {
                frame_id: i.0 .0,
                src: src(i.0),
                offset: i.1,
                iops: None,
            },
            confidence: c.min(1.0),
            evidence: ev,
        });
    }
    found
}
