//! The user's own pattern and body (issue 24), in one test binary: garments of pieces imported
//! from pattern software ([`imported`]) and a body scan as a scene's body ([`scan_body`]).

mod imported;
mod scan_body;
