//! One error type for every job. Each variant is one *kind* of failure with a stable slug
//! ([`Error::kind`]) that the service turns into the `type` of an RFC 9457 problem and the CLI prints.
//! Messages say what is wrong and where (line, accessor, face index), because the caller cannot
//! see inside our parser.

use std::fmt;

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Where in an input file a problem was found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Location {
    /// 1-based line of a text format (OBJ, OFF, ASCII PLY/STL).
    Line(usize),
    /// Byte offset in a binary format (binary PLY/STL, GLB chunk).
    Byte(usize),
    /// A glTF object by its JSON path, e.g. `accessors[3]` or `meshes[0].primitives[1]`.
    Gltf(String),
    /// A face by its index in the input.
    Face(usize),
    /// A vertex by its index in the input.
    Vertex(usize),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(l) => write!(f, "line {l}"),
            Location::Byte(b) => write!(f, "byte {b}"),
            Location::Gltf(p) => write!(f, "{p}"),
            Location::Face(i) => write!(f, "face {i}"),
            Location::Vertex(i) => write!(f, "vertex {i}"),
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The bytes are not any format we read (or a format we deliberately do not read).
    #[error("unsupported format: {0}")]
    UnsupportedFormat(String),

    /// The file claims to be a format but breaks its rules.
    #[error("malformed {format} at {location}: {message}")]
    Malformed { format: &'static str, location: Location, message: String },

    /// A glTF `uri` pointing at a file or URL: we never resolve those in uploaded data.
    #[error("external reference refused at {location}: {message}")]
    ExternalReference { location: Location, message: String },

    /// Input is readable but its geometry is unusable (NaN coordinates, index out of range, …).
    #[error("invalid mesh at {location}: {message}")]
    InvalidMesh { location: Location, message: String },

    /// Parameters failed validation; `field` names the parameter.
    #[error("invalid parameter `{field}`: {message}")]
    InvalidParams { field: String, message: String },

    /// A configured limit (vertices, faces, iterations, bytes, …) was exceeded.
    #[error("{what} exceeds the limit: {actual} > {limit}")]
    TooLarge { what: String, limit: u64, actual: u64 },

    /// The mesh's topology does not allow the job (not manifold, wrong genus, open where closed is needed).
    #[error("unsupported topology: {0}")]
    Topology(String),

    /// A numerical step failed (singular system, factorisation failure, no convergence).
    #[error("numerical failure in {stage}: {message}")]
    Numerical { stage: String, message: String },

    #[error("job cancelled")]
    Cancelled,

    #[error("job exceeded its time limit")]
    TimedOut,

    /// A bug on our side; never the caller's fault.
    #[error("internal error: {0}")]
    Internal(String),
}

impl Error {
    /// Stable slug naming the kind of failure; used as the problem `type` suffix and CLI prefix.
    pub fn kind(&self) -> &'static str {
        match self {
            Error::UnsupportedFormat(_) => "unsupported-format",
            Error::Malformed { .. } => "malformed-input",
            Error::ExternalReference { .. } => "external-reference",
            Error::InvalidMesh { .. } => "invalid-mesh",
            Error::InvalidParams { .. } => "invalid-params",
            Error::TooLarge { .. } => "too-large",
            Error::Topology(_) => "unsupported-topology",
            Error::Numerical { .. } => "numerical-failure",
            Error::Cancelled => "cancelled",
            Error::TimedOut => "timed-out",
            Error::Internal(_) => "internal",
        }
    }

    pub fn malformed(format: &'static str, location: Location, message: impl Into<String>) -> Self {
        Error::Malformed { format, location, message: message.into() }
    }

    pub fn params(field: impl Into<String>, message: impl Into<String>) -> Self {
        Error::InvalidParams { field: field.into(), message: message.into() }
    }

    pub fn numerical(stage: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Numerical { stage: stage.into(), message: message.into() }
    }
}
