//! `facet fit --shard I/N`: a sweep of fits split over processes or machines. Shard I fits the
//! inputs whose index k (in command-line order, from 0) has k mod N = I, and records what it did
//! in a manifest, `shard-I-of-N.facet-shard.json`, beside the fits; `facet fit --summary` reads
//! the manifests back ([`super::summary`]).
//!
//! The manifest:
//! `{"facet_shard": {"index", "count", "total_inputs", "facet_version", "settings"},
//!   "inputs": [{"index", "input", "json"} or {"index", "input", "error"}]}`.
//! It is written last, once every input of the shard is done: a shard that did not finish has
//! none, and a summary then reports it missing.

use serde_json::{Value, json};

/// How a shard manifest's file name ends. No fit's file can end so: fit files are
/// `NAME.json` and `NAME.tables.csv`, and a fit whose file stem would end in `.facet-shard` is
/// written as `…_facet-shard.json` ([`fit_stem`]).
pub const MANIFEST_SUFFIX: &str = ".facet-shard.json";

/// A fit's file stem that can never be taken for a manifest's: a stem ending in `.facet-shard`
/// (any case) has that dot made `_`.
pub fn fit_stem(mut stem: String) -> String {
    let tail = ".facet-shard";
    if stem.to_ascii_lowercase().ends_with(tail) {
        let at = stem.len() - tail.len();
        stem.replace_range(at..at + 1, "_");
    }
    stem
}

/// The most shards of a sweep (far more than inputs fit on a command line).
pub const MAX_SHARDS: usize = 1 << 20;

/// `--shard I/N`: the I-th of N shards, from 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// I, below `count`.
    pub index: usize,
    /// N, at least 1.
    pub count: usize,
}

impl Shard {
    /// Whether the input at `k` (command-line order, from 0) is this shard's.
    pub fn holds(self, k: usize) -> bool {
        k % self.count == self.index
    }

    /// The file name of this shard's manifest: `shard-I-of-N.facet-shard.json`.
    pub fn manifest_name(self) -> String {
        format!("shard-{}-of-{}{MANIFEST_SUFFIX}", self.index, self.count)
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "shard {} of {}", self.index, self.count)
    }
}

/// The value parser of `--shard`: `I/N` with N ≥ 1 and I < N.
pub fn parse_shard(s: &str) -> Result<Shard, String> {
    let whole = |t: &str| t.trim().parse::<usize>().ok();
    let Some((Some(index), Some(count))) = s.split_once('/').map(|(i, n)| (whole(i), whole(n)))
    else {
        return Err(format!(
            "`{s}` is not I/N: shard I of N, two whole numbers, I from 0 to N − 1 (0/4 … 3/4)"
        ));
    };
    if count == 0 {
        return Err(format!("{s}: N must be at least 1"));
    }
    if count > MAX_SHARDS {
        return Err(format!("{s}: N is at most {MAX_SHARDS}"));
    }
    if index >= count {
        return Err(format!(
            "{s}: I must be below N (shards are numbered from 0: 0/{count} … {}/{count})",
            count - 1
        ));
    }
    Ok(Shard { index, count })
}

/// What became of one input of a shard.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    /// The input's index on the command line, from 0.
    pub index: usize,
    /// The input as given.
    pub input: String,
    /// The fit's file name in the shard's folder, or the error that stopped it.
    pub outcome: Result<String, String>,
}

/// A shard manifest.
#[derive(Clone, Debug, PartialEq)]
pub struct Manifest {
    /// Which shard.
    pub shard: Shard,
    /// Inputs of the whole sweep.
    pub total_inputs: usize,
    /// The Facet that wrote it.
    pub facet_version: String,
    /// The fit settings every shard of one sweep shares ([`settings`]).
    pub settings: String,
    /// The shard's inputs, by index.
    pub entries: Vec<Entry>,
}

/// The text that identifies a sweep's fit settings in its manifests: every option of
/// `facet fit` that changes a fit, as the fit configuration's debug text, the `--backend`
/// asked for and the neural proxies' file (by file name: shards may run on machines that keep
/// it in different folders).
pub fn settings(
    cfg: &facet_fit::FitConfig,
    backend: &str,
    nbrdf: Option<&std::path::Path>,
) -> String {
    let proxies = nbrdf
        .and_then(|p| p.file_name())
        .map_or("embedded".into(), |n| n.to_string_lossy().into_owned());
    format!("{cfg:?}; backend {backend}; nbrdf {proxies}")
}

impl Manifest {
    /// The manifest as pretty JSON.
    pub fn to_json(&self) -> String {
        let inputs: Vec<Value> = self
            .entries
            .iter()
            .map(|e| match &e.outcome {
                Ok(json) => json!({ "index": e.index, "input": e.input, "json": json }),
                Err(error) => json!({ "index": e.index, "input": e.input, "error": error }),
            })
            .collect();
        let v = json!({
            "facet_shard": {
                "index": self.shard.index,
                "count": self.shard.count,
                "total_inputs": self.total_inputs,
                "facet_version": self.facet_version,
                "settings": self.settings,
            },
            "inputs": inputs,
        });
        serde_json::to_string_pretty(&v).expect("a JSON value always serialises") + "\n"
    }

    /// A manifest from its JSON (an object with a `facet_shard` key); the problem in words
    /// when a field is missing or of the wrong type, or the inputs are not the shard's.
    pub fn parse(v: &Value) -> Result<Manifest, String> {
        let head = &v["facet_shard"];
        let number = |o: &Value, key: &str| {
            o[key]
                .as_u64()
                .and_then(|n| usize::try_from(n).ok())
                .ok_or_else(|| format!("`{key}` is not a whole number"))
        };
        let text = |o: &Value, key: &str| {
            o[key]
                .as_str()
                .map(str::to_owned)
                .ok_or_else(|| format!("`{key}` is not a string"))
        };
        let shard = parse_shard(&format!(
            "{}/{}",
            number(head, "index")?,
            number(head, "count")?
        ))?;
        let total_inputs = number(head, "total_inputs")?;
        let entries = v["inputs"]
            .as_array()
            .ok_or("`inputs` is not a list")?
            .iter()
            .map(|e| {
                let outcome = match (e["json"].as_str(), e["error"].as_str()) {
                    (Some(json), None) => Ok(json.to_owned()),
                    (None, Some(error)) => Err(error.to_owned()),
                    (Some(_), Some(_)) => {
                        return Err("an input has both `json` and `error` (one of them)".to_owned());
                    }
                    (None, None) => {
                        return Err("an input has neither `json` nor `error` (text)".to_owned());
                    }
                };
                Ok(Entry {
                    index: number(e, "index")?,
                    input: text(e, "input")?,
                    outcome,
                })
            })
            .collect::<Result<Vec<_>, String>>()?;
        // The entries are the shard's inputs, each once, in order.
        let want = (shard.index..total_inputs).step_by(shard.count);
        if !entries.iter().map(|e| e.index).eq(want) {
            return Err(format!(
                "its inputs are not those of {shard} of {total_inputs} inputs"
            ));
        }
        Ok(Manifest {
            shard,
            total_inputs,
            facet_version: text(head, "facet_version")?,
            settings: text(head, "settings")?,
            entries,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shard_values() {
        assert_eq!(parse_shard("1/3"), Ok(Shard { index: 1, count: 3 }));
        assert_eq!(parse_shard("0/1"), Ok(Shard { index: 0, count: 1 }));
        assert!(
            parse_shard("3/3")
                .unwrap_err()
                .contains("I must be below N")
        );
        assert!(
            parse_shard("1/0")
                .unwrap_err()
                .contains("N must be at least 1")
        );
        for bad in ["x", "1", "-1/3", "1/3/4", "a/b", ""] {
            assert!(
                parse_shard(bad).unwrap_err().contains("is not I/N"),
                "{bad}"
            );
        }
        let s = parse_shard("2/3").unwrap();
        assert!(s.holds(2) && s.holds(5) && !s.holds(3));
        assert_eq!(s.manifest_name(), "shard-2-of-3.facet-shard.json");
    }

    #[test]
    fn no_fit_stem_ends_like_a_manifest() {
        assert_eq!(fit_stem("gold".into()), "gold");
        assert_eq!(
            fit_stem("shard-0-of-3.facet-shard".into()),
            "shard-0-of-3_facet-shard"
        );
        assert_eq!(fit_stem("x.FACET-SHARD".into()), "x_FACET-SHARD");
        assert_eq!(fit_stem(".facet-shard".into()), "_facet-shard");
    }

    #[test]
    fn a_manifest_reads_back_and_its_inputs_are_checked() {
        let m = Manifest {
            shard: Shard { index: 1, count: 2 },
            total_inputs: 4,
            facet_version: "0.1.0".into(),
            settings: "s".into(),
            entries: vec![
                Entry {
                    index: 1,
                    input: "nbrdf:a".into(),
                    outcome: Ok("a.json".into()),
                },
                Entry {
                    index: 3,
                    input: "b.binary".into(),
                    outcome: Err("b.binary: truncated".into()),
                },
            ],
        };
        let v: Value = serde_json::from_str(&m.to_json()).unwrap();
        assert_eq!(Manifest::parse(&v), Ok(m.clone()));
        // An entry with both outcomes, or neither, is named for what it is.
        let mut both = v.clone();
        both["inputs"][0]["error"] = "x".into();
        assert!(
            Manifest::parse(&both)
                .unwrap_err()
                .contains("both `json` and `error`")
        );
        let mut neither = v.clone();
        neither["inputs"][0].as_object_mut().unwrap().remove("json");
        assert!(Manifest::parse(&neither).unwrap_err().contains("neither"));
        let mut short = m;
        short.entries.pop();
        let v: Value = serde_json::from_str(&short.to_json()).unwrap();
        assert!(
            Manifest::parse(&v)
                .unwrap_err()
                .contains("not those of shard 1 of 2")
        );
    }
}
