//! CPU reference renderer and the pieces shared with the GPU player (camera, tone mapping).

pub mod tonemap;
