//! Why a figure could not be drawn or written ([`crate::plots`] and the
//! comparison and sweep figures built on it).

use std::path::{Path, PathBuf};

/// A figure could not be drawn or written.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// plotters could not draw (its message: its errors are generic over
    /// the backend).
    #[error("{0}")]
    Draw(String),
    /// The data hold nothing the figure can show.
    #[error("nothing to draw: {0}")]
    Empty(&'static str),
    /// Drawing or writing one figure's file failed.
    #[error("{}: {source}", path.display())]
    Figure {
        /// The figure's file.
        path: PathBuf,
        /// Why.
        source: Box<PlotError>,
    },
    /// The figures' folder could not be made.
    #[error("{}: {source}", path.display())]
    Folder {
        /// The folder.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

impl PlotError {
    /// Names the figure file `path` in an error drawing it.
    pub fn in_file(path: &Path) -> impl FnOnce(PlotError) -> PlotError + '_ {
        move |e| PlotError::Figure {
            path: path.to_path_buf(),
            source: Box::new(e),
        }
    }

    /// Names the folder `path` in an error making it.
    pub fn folder(path: &Path) -> impl FnOnce(std::io::Error) -> PlotError + '_ {
        move |source| PlotError::Folder {
            path: path.to_path_buf(),
            source,
        }
    }
}
