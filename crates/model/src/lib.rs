//! plantwide-model
