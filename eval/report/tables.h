#pragma once
// The report's tables, each built from the scenes' scores.

#include <optional>
#include <vector>

#include "eval/report/document.h"
#include "eval/report/paper_numbers.h"
#include "eval/report/scene_data.h"

namespace eval {

// mIoU / mBIoU (or accuracy) per scene and their mean, the paper's figures
// of the same pseudo-labels beside ours when the dataset is one of its.
Table dataset_table(const std::vector<SceneData>& scenes, Dataset d);

// The paper's ablation layout: baseline against dual opacity, oracle and
// query mode, means over the scenes; none when there is no baseline row.
std::optional<Table> ablation_table(const std::vector<SceneData>& scenes, Dataset d);

// Per query (class): the object each row chose and its scores.
Table query_table(const SceneData& s);

// The query similarities of op2gs-query, when it ran.
std::optional<Table> similarity_table(const SceneData& s);

// Floaters and label contamination (op2gs-floaters), when measured.
std::vector<Table> floater_tables(const SceneReportInput& in);

}  // namespace eval
