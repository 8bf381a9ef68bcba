//! CARMEN's collision file (`robot_collision_file`): line 1 the circle count, line 2 the number
//! of levels minus one, then one `x y r level` line per circle (metres, vehicle frame). The file
//! holds no heights: readers take the heights of interest as a parameter.

use std::path::Path;

use crate::error::{Error, Result};

/// Reads a CARMEN collision file (thin wrapper over [`from_carmen_str`]).
pub fn from_carmen_file(path: &Path, level_heights_m: &[f64]) -> Result<mapper::CollisionModel> {
    let text = std::fs::read_to_string(path).map_err(|error| Error::Io {
        path: path.to_path_buf(),
        error,
    })?;
    from_carmen_str(&text, &path.display().to_string(), level_heights_m)
}

/// Parses CARMEN collision text; `file` names the source in errors. `level_heights_m` must have
/// as many heights as the file has levels.
pub fn from_carmen_str(
    text: &str,
    file: &str,
    level_heights_m: &[f64],
) -> Result<mapper::CollisionModel> {
    let err = |line: usize, message: String| Error::Carmen {
        file: file.to_string(),
        line,
        message,
    };
    // Non-blank lines with their 1-based numbers; trailing blank lines are fine.
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty());
    let last_line = text.lines().count().max(1);
    let mut header = |what: &str| -> Result<(usize, usize)> {
        let (n, l) = lines
            .next()
            .ok_or_else(|| err(last_line, format!("missing {what}")))?;
        let v = l
            .parse::<usize>()
            .map_err(|_| err(n, format!("{what} must be a whole number, got `{l}`")))?;
        Ok((n, v))
    };
    let (count_line, count) = header("circle count")?;
    let (levels_line, extra_levels) = header("number of levels - 1")?;
    let levels = extra_levels + 1;
    if levels != level_heights_m.len() {
        return Err(err(
            levels_line,
            format!(
                "the file has {levels} level(s) but {} height(s) of interest were given",
                level_heights_m.len()
            ),
        ));
    }
    let mut circles = Vec::with_capacity(count);
    for (n, l) in lines {
        let fields: Vec<&str> = l.split_whitespace().collect();
        let [x, y, r, level] = fields.as_slice() else {
            return Err(err(
                n,
                format!("expected `x y r level`, got {} field(s)", fields.len()),
            ));
        };
        let num = |s: &str, what: &str| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| err(n, format!("{what} `{s}` is not a finite number")))
        };
        let (x_m, y_m, radius_m) = (num(x, "x")?, num(y, "y")?, num(r, "radius")?);
        if radius_m <= 0.0 {
            return Err(err(n, format!("radius {radius_m} must be > 0")));
        }
        let level = level
            .parse::<usize>()
            .map_err(|_| err(n, format!("level `{level}` must be a whole number")))?;
        if level >= levels {
            return Err(err(
                n,
                format!("level {level} but the file declares {levels} level(s)"),
            ));
        }
        circles.push(mapper::Circle {
            x_m,
            y_m,
            radius_m,
            level,
        });
    }
    if circles.len() != count {
        return Err(err(
            count_line,
            format!("declares {count} circle(s) but {} follow", circles.len()),
        ));
    }
    mapper::CollisionModel::new(circles, level_heights_m.to_vec()).map_err(|error| Error::Model {
        context: file.to_string(),
        error,
    })
}

/// The model in CARMEN's format (numbers in Rust's shortest round-trip form).
pub fn to_carmen_string(model: &mapper::CollisionModel) -> String {
    let mut s = format!(
        "{}\n{}\n",
        model.circles().len(),
        model.level_count().saturating_sub(1)
    );
    for c in model.circles() {
        s.push_str(&format!("{} {} {} {}\n", c.x_m, c.y_m, c.radius_m, c.level));
    }
    s
}

/// Writes the model in CARMEN's format, atomically.
pub fn write_carmen_file(path: &Path, model: &mapper::CollisionModel) -> Result<()> {
    crate::io::write_atomic(path, to_carmen_string(model).as_bytes())
}
