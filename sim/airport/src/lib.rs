//! taxi-sim's airports: an X-Plane `apt.dat` (versions 1000 through 1200) read into a local
//! metric frame at the airport's datum, its taxi routing network, and taxi routes along named
//! taxiways, on the painted centreline where the network strays from it, rounded into paths an
//! aircraft can drive; from a stand, the push-back that leaves it.
//!
//! Pure geometry and graphs: no simulator, renderer or scenario files (`sim` builds a world from
//! an [`Airport`]).

pub mod apt_dat;
pub mod bezier;
mod error;
pub mod geodesy;
pub mod model;
pub mod network;
pub mod paint;
pub mod path;
pub mod pushback;
pub mod route;
mod row;
pub mod size;

pub use error::AirportError;
pub use geodesy::{LatLon, LocalFrame};
pub use model::{Airport, Pavement, Runway, Sign, Stand, Surface};
pub use network::{Edge, EdgeClass, Network, NetworkRoute, Node};
pub use path::{PathOptions, TaxiPath, smooth};
pub use pushback::{Tow, leave_stand};
pub use route::{Place, RouteRequest, find, find_on_network, hold_points};
pub use size::SizeClass;
