//! The crate's typed errors: every bad description names its file, and its link or line.

use std::path::PathBuf;

/// Result alias for this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// What can go wrong reading a vehicle description, fitting it, or exchanging a CARMEN file.
///
/// `file` is the path (or the label given to a `from_str` function) of the offending input.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read or written.
    #[error("{}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error (in the message, not repeated as a source).
        error: std::io::Error,
    },
    /// urdf-rs rejected the XML.
    #[error("{file}: invalid URDF: {message}")]
    Urdf {
        /// The URDF file.
        file: String,
        /// urdf-rs's message.
        message: String,
    },
    /// The sidecar TOML could not be parsed (syntax, unknown field, wrong type).
    #[error("{file}:{line}:{column}: {message}")]
    Toml {
        /// The TOML file.
        file: String,
        /// 1-based line of the error.
        line: usize,
        /// 1-based column of the error.
        column: usize,
        /// toml's message.
        message: String,
    },
    /// A sidecar field parsed but has a value that makes no sense.
    #[error("{file}: field `{field}`: {message}")]
    Field {
        /// The TOML file.
        file: String,
        /// The field, e.g. `motion.wheelbase_m`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// A joint names a parent or child link that the description does not have.
    #[error("{file}: joint `{joint}` names {role} link `{link}`, which does not exist")]
    MissingLink {
        /// The URDF file.
        file: String,
        /// The joint.
        joint: String,
        /// `parent` or `child`.
        role: &'static str,
        /// The missing link.
        link: String,
    },
    /// The link tree is malformed (duplicate link, link with two parents, no or several roots).
    #[error("{file}: link `{link}`: {message}")]
    Tree {
        /// The URDF file.
        file: String,
        /// The link at fault.
        link: String,
        /// What is wrong.
        message: String,
    },
    /// A geometry size or an origin is zero, negative or not finite.
    #[error("{file}: link `{link}`: {what} = {value} (must be finite{positive})", positive = if *.must_be_positive { " and > 0" } else { "" })]
    BadNumber {
        /// The URDF file.
        file: String,
        /// The link holding the value.
        link: String,
        /// Which value, e.g. `collision 0 box size x`.
        what: String,
        /// The value found.
        value: f64,
        /// Whether the value must also be > 0 (sizes) or only finite (origins).
        must_be_positive: bool,
    },
    /// A collision geometry this crate does not turn into shapes (meshes).
    #[error(
        "{file}: link `{link}`: collision {index} is a {geometry}, which is not supported (use boxes, cylinders, capsules or spheres)"
    )]
    UnsupportedGeometry {
        /// The URDF file.
        file: String,
        /// The link.
        link: String,
        /// Index of the `<collision>` element in the link.
        index: usize,
        /// The geometry kind, e.g. `mesh`.
        geometry: String,
    },
    /// No link has any collision geometry: there is nothing to fit circles to.
    #[error("{file}: no link has collision geometry")]
    NoCollisionGeometry {
        /// The URDF file.
        file: String,
    },
    /// A CARMEN collision file line could not be read.
    #[error("{file}:{line}: {message}")]
    Carmen {
        /// The collision file.
        file: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// Fitting options or the fit itself are not possible.
    #[error("fit: {0}")]
    Fit(String),
    /// An unknown shipped vehicle name.
    #[error("no shipped vehicle named `{name}` (known: {known})")]
    UnknownVehicle {
        /// The name asked for.
        name: String,
        /// The shipped names, comma separated.
        known: String,
    },
    /// The collision model type rejected the circles or heights.
    #[error("{context}: {error}")]
    Model {
        /// Where the model was being built.
        context: String,
        /// The mapper error (in the message, not repeated as a source).
        error: mapper::MapError,
    },
}

impl Error {
    /// A `Toml` error located from a toml error's byte span in `text`.
    pub(crate) fn toml(file: &str, text: &str, err: &toml::de::Error) -> Self {
        let offset = err.span().map_or(0, |s| s.start).min(text.len());
        let before = &text[..text.floor_char_boundary(offset)];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        Error::Toml {
            file: file.to_string(),
            line,
            column,
            message: err.message().to_string(),
        }
    }
}
