//! Placeholder: polygonisation of a freeform field (being written).
