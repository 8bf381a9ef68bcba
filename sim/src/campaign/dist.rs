//! Variations: a campaign's TOML values in which any value may be a distribution
//! (`{ uniform = [lo, hi] }`, `{ normal = { mean, sd, min, max } }`, `{ choice = [...] }`,
//! `{ int = [lo, hi] }`), compiled into a [`Node`] tree whose every random draw has a fixed
//! dimension of the unit hypercube. A variant is a point `u` of that cube: the samplers choose
//! `u`, [`Node::sample`] maps it through each distribution's inverse CDF. Every branch of a
//! `choice` keeps its dimensions whether chosen or not, so the layout is the same for every
//! variant (what grid, Halton and the cross-entropy search need).

use std::collections::BTreeMap;

use serde::Serialize;
use toml::Value;

/// The names of a distribution table's single key.
const DISTRIBUTIONS: [&str; 4] = ["uniform", "normal", "choice", "int"];

/// One random dimension: what the samplers need to know of it.
#[derive(Clone, Debug, Serialize)]
pub struct Dimension {
    /// Where it is, e.g. `obstacles.cone_1.along_m`.
    pub label: String,
    /// Categories for a discrete draw (`choice`, `int`), `None` for a continuous one.
    pub categories: Option<usize>,
}

/// A continuous distribution on the real line, drawn by inverse CDF from `u` in [0, 1).
#[derive(Clone, Debug, PartialEq)]
pub enum Continuous {
    /// Uniform on [lo, hi].
    Uniform {
        /// Lower bound.
        lo: f64,
        /// Upper bound.
        hi: f64,
    },
    /// Normal, truncated to [min, max].
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation (> 0).
        sd: f64,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
}

impl Continuous {
    /// The value at `u` in [0, 1).
    pub fn at(&self, u: f64) -> f64 {
        match *self {
            Continuous::Uniform { lo, hi } => lo + u * (hi - lo),
            Continuous::Normal { mean, sd, min, max } => {
                let (a, b) = (phi((min - mean) / sd), phi((max - mean) / sd));
                (mean + sd * phi_inverse(a + u * (b - a))).clamp(min, max)
            }
        }
    }
}

/// The standard normal CDF.
pub fn phi(x: f64) -> f64 {
    0.5 * libm::erfc(-x / std::f64::consts::SQRT_2)
}

/// The standard normal quantile, by bisection on [`phi`] (60 halvings of [-40, 40]: far below
/// any tolerance a placement needs, and a few microseconds a draw).
pub fn phi_inverse(p: f64) -> f64 {
    let (mut lo, mut hi) = (-40.0_f64, 40.0_f64);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if phi(mid) < p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// A compiled campaign value.
#[derive(Clone, Debug)]
pub enum Node {
    /// A value as written.
    Fixed(Value),
    /// A continuous draw at dimension `dim`.
    Draw {
        /// Its dimension.
        dim: usize,
        /// Its distribution.
        dist: Continuous,
    },
    /// An integer in [lo, hi] at dimension `dim`.
    Int {
        /// Its dimension.
        dim: usize,
        /// Lower bound.
        lo: i64,
        /// Upper bound (inclusive).
        hi: i64,
    },
    /// One of `items` at dimension `dim`, each item itself compiled.
    Choice {
        /// Its dimension.
        dim: usize,
        /// The items.
        items: Vec<Node>,
    },
    /// A table, key by key.
    Table(Vec<(String, Node)>),
    /// An array, item by item.
    Array(Vec<Node>),
}

/// Compiles values, handing out dimensions in order.
#[derive(Debug, Default)]
pub struct Layout {
    /// Every dimension handed out, in order.
    pub dims: Vec<Dimension>,
}

impl Layout {
    fn push(&mut self, label: &str, categories: Option<usize>) -> usize {
        self.dims.push(Dimension {
            label: label.to_string(),
            categories,
        });
        self.dims.len() - 1
    }

    /// Compiles `value`, found at `label`; the error names the label and what is wrong.
    pub fn compile(&mut self, label: &str, value: &Value) -> Result<Node, String> {
        match value {
            Value::Table(t)
                if t.len() == 1
                    && DISTRIBUTIONS
                        .contains(&t.keys().next().unwrap_or(&String::new()).as_str()) =>
            {
                let (name, arg) = t.iter().next().expect("one key");
                self.distribution(label, name, arg)
            }
            Value::Table(t) => Ok(Node::Table(
                t.iter()
                    .map(|(k, v)| Ok((k.clone(), self.compile(&format!("{label}.{k}"), v)?)))
                    .collect::<Result<_, String>>()?,
            )),
            Value::Array(a) => Ok(Node::Array(
                a.iter()
                    .enumerate()
                    .map(|(i, v)| self.compile(&format!("{label}[{i}]"), v))
                    .collect::<Result<_, String>>()?,
            )),
            other => Ok(Node::Fixed(other.clone())),
        }
    }

    fn distribution(&mut self, label: &str, name: &str, arg: &Value) -> Result<Node, String> {
        let numbers = |what: &str| -> Result<(f64, f64), String> {
            match arg
                .as_array()
                .map(|a| a.iter().map(as_f64).collect::<Vec<_>>())
            {
                Some(v) if v.len() == 2 && v.iter().all(Option::is_some) => {
                    let (lo, hi) = (v[0].unwrap_or(0.0), v[1].unwrap_or(0.0));
                    if lo.is_finite() && hi.is_finite() && lo <= hi {
                        Ok((lo, hi))
                    } else {
                        Err(format!(
                            "{label}: {what} = [{lo}, {hi}]: needs finite lo <= hi"
                        ))
                    }
                }
                _ => Err(format!("{label}: {what} takes two numbers [lo, hi]")),
            }
        };
        match name {
            "uniform" => {
                let (lo, hi) = numbers("uniform")?;
                let dim = self.push(label, None);
                Ok(Node::Draw {
                    dim,
                    dist: Continuous::Uniform { lo, hi },
                })
            }
            "int" => {
                let (lo, hi) = numbers("int")?;
                if lo.fract() != 0.0 || hi.fract() != 0.0 || hi - lo > 1e9 {
                    return Err(format!("{label}: int = [{lo}, {hi}]: needs two integers"));
                }
                let dim = self.push(label, Some((hi - lo) as usize + 1));
                Ok(Node::Int {
                    dim,
                    lo: lo as i64,
                    hi: hi as i64,
                })
            }
            "normal" => self.normal(label, arg),
            "choice" => {
                let items = arg
                    .as_array()
                    .filter(|a| !a.is_empty())
                    .ok_or_else(|| format!("{label}: choice takes a non-empty array of values"))?;
                let dim = self.push(label, Some(items.len()));
                let items = items
                    .iter()
                    .enumerate()
                    .map(|(i, v)| self.compile(&format!("{label}#{i}"), v))
                    .collect::<Result<_, String>>()?;
                Ok(Node::Choice { dim, items })
            }
            _ => unreachable!("checked against DISTRIBUTIONS"),
        }
    }

    fn normal(&mut self, label: &str, arg: &Value) -> Result<Node, String> {
        let t = arg.as_table().ok_or_else(|| {
            format!("{label}: normal takes {{ mean, sd, min, max }} (a truncated normal)")
        })?;
        let get = |k: &str| {
            t.get(k)
                .and_then(as_f64)
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("{label}: normal needs a finite number `{k}`"))
        };
        if let Some(k) = t
            .keys()
            .find(|k| !["mean", "sd", "min", "max"].contains(&k.as_str()))
        {
            return Err(format!(
                "{label}: normal: unknown key `{k}` (expected mean, sd, min, max)"
            ));
        }
        let (mean, sd, min, max) = (get("mean")?, get("sd")?, get("min")?, get("max")?);
        if sd <= 0.0 || min >= max || mean < min || mean > max {
            return Err(format!(
                "{label}: normal needs sd > 0 and min <= mean <= max with min < max (got mean {mean}, sd {sd}, min {min}, max {max})"
            ));
        }
        let dim = self.push(label, None);
        Ok(Node::Draw {
            dim,
            dist: Continuous::Normal { mean, sd, min, max },
        })
    }
}

fn as_f64(v: &Value) -> Option<f64> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

/// Rounds a drawn number to 1 mm (or 1e-6 of its unit): files and results stay readable, and
/// the value written is the value run.
fn tidy(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

impl Node {
    /// The value at point `u` of the unit cube; each draw is recorded in `drawn` under its label.
    pub fn sample(&self, u: &[f64], layout: &Layout, drawn: &mut BTreeMap<String, Value>) -> Value {
        match self {
            Node::Fixed(v) => v.clone(),
            Node::Draw { dim, dist } => {
                let v = Value::Float(tidy(dist.at(u[*dim])));
                drawn.insert(layout.dims[*dim].label.clone(), v.clone());
                v
            }
            Node::Int { dim, lo, hi } => {
                let n = (hi - lo + 1) as f64;
                let v = Value::Integer(lo + ((u[*dim] * n).floor() as i64).min(hi - lo));
                drawn.insert(layout.dims[*dim].label.clone(), v.clone());
                v
            }
            Node::Choice { dim, items } => {
                let i = ((u[*dim] * items.len() as f64).floor() as usize).min(items.len() - 1);
                let v = items[i].sample(u, layout, drawn);
                // A scalar choice is recorded as its value; a table's as its index.
                let shown = match &v {
                    Value::Table(_) | Value::Array(_) => Value::Integer(i as i64),
                    other => other.clone(),
                };
                drawn.insert(layout.dims[*dim].label.clone(), shown);
                v
            }
            Node::Table(entries) => Value::Table(
                entries
                    .iter()
                    .map(|(k, n)| (k.clone(), n.sample(u, layout, drawn)))
                    .collect(),
            ),
            Node::Array(items) => {
                Value::Array(items.iter().map(|n| n.sample(u, layout, drawn)).collect())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn compile(text: &str) -> (Layout, Node) {
        let v: toml::Table = toml::from_str(text).unwrap();
        let mut layout = Layout::default();
        let node = layout.compile("x", &Value::Table(v)).unwrap();
        (layout, node)
    }

    #[test]
    fn quantile_inverts_the_cdf() {
        for x in [-3.0, -1.0, 0.0, 0.5, 2.5] {
            assert!((phi_inverse(phi(x)) - x).abs() < 1e-9, "{x}");
        }
        assert!((phi(1.959964) - 0.975).abs() < 1e-6);
    }

    #[test]
    fn draws_map_the_unit_interval_onto_their_support() {
        let (layout, node) = compile(
            "a = { uniform = [2.0, 4.0] }\nb = { int = [1, 3] }\nc = { choice = ['cone', { kind = 'box', h = { uniform = [0.0, 1.0] } }] }\nd = { normal = { mean = 0.0, sd = 1.0, min = -1.0, max = 2.0 } }\ne = [1.0, { uniform = [0.0, 10.0] }]",
        );
        let labels: Vec<_> = layout.dims.iter().map(|d| d.label.as_str()).collect();
        assert_eq!(labels, ["x.a", "x.b", "x.c", "x.c#1.h", "x.d", "x.e[1]"]);
        let mut drawn = BTreeMap::new();
        let v = node.sample(&[0.5, 0.99, 0.7, 0.25, 0.5, 0.1], &layout, &mut drawn);
        let t = v.as_table().unwrap();
        assert_eq!(t["a"].as_float(), Some(3.0));
        assert_eq!(t["b"].as_integer(), Some(3));
        assert_eq!(t["c"]["kind"].as_str(), Some("box"));
        assert_eq!(t["c"]["h"].as_float(), Some(0.25));
        // The median of a normal truncated to [-1, 2] lies above its mean.
        let d = t["d"].as_float().unwrap();
        assert!(d > 0.0 && d < 0.5, "{d}");
        assert_eq!(t["e"][1].as_float(), Some(1.0));
        assert_eq!(drawn["x.c"].as_integer(), Some(1));
        let (_, lo) = (0, node.sample(&[0.0; 6], &layout, &mut drawn));
        assert_eq!(lo["d"].as_float(), Some(-1.0));
        assert_eq!(lo["c"].as_str(), Some("cone"));
    }

    #[test]
    fn bad_distributions_name_their_place() {
        let mut layout = Layout::default();
        let v: toml::Table = toml::from_str("a = { uniform = [4.0, 2.0] }").unwrap();
        let e = layout.compile("obstacles.c", &Value::Table(v)).unwrap_err();
        assert!(e.contains("obstacles.c.a: uniform = [4, 2]"), "{e}");
        let v: toml::Table =
            toml::from_str("a = { normal = { mean = 0.0, sd = 0.0, min = -1.0, max = 1.0 } }")
                .unwrap();
        let e = layout.compile("p", &Value::Table(v)).unwrap_err();
        assert!(e.contains("p.a: normal needs sd > 0"), "{e}");
    }
}
