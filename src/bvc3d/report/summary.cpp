#include "bvc3d/report/summary.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>

#include "bvc3d/analysis/metrics.hpp"
#include "bvc3d/analysis/trial_metrics.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/csv.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d {

namespace {

std::string num(double v) { return format_number(v); }

std::string fixed(double v, int digits) {
    if (std::isnan(v)) return "–";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
}

// The swept keys of a table, in first-seen order.
template <class Row>
std::vector<std::string> swept_keys(const std::vector<Row>& rows) {
    std::vector<std::string> keys;
    for (const auto& r : rows)
        for (const auto& [k, v] : r.swept)
            if (std::find(keys.begin(), keys.end(), k) == keys.end()) keys.push_back(k);
    return keys;
}

template <class Row>
std::string swept_value(const Row& r, const std::string& key) {
    for (const auto& [k, v] : r.swept)
        if (k == key) return v;
    return "";
}

}  // namespace

TrialSummaryRow read_summary(const std::filesystem::path& file) {
    std::vector<std::string> parameters;
    for (const auto& f : analysis::AnalysisParams::table().fields()) parameters.push_back(f.key);
    return read_trial_summary(file, analysis::metric_names(), parameters);
}

std::vector<TrialSummaryRow> read_summaries(const std::vector<std::filesystem::path>& files) {
    std::vector<TrialSummaryRow> rows;
    for (const auto& f : files) rows.push_back(read_summary(f));
    // Metrics of one kind of trial only (3-D: flying agents) that no trial has are left out, so a
    // ground experiment's tables are what they always were.
    for (const auto& m : analysis::metric_table()) {
        if (m.dims == 0) continue;
        const bool any = std::any_of(rows.begin(), rows.end(), [&](const TrialSummaryRow& r) {
            return std::any_of(r.metrics.begin(), r.metrics.end(),
                               [&](const auto& v) { return v.first == m.name && !std::isnan(v.second); });
        });
        if (any) continue;
        for (auto& r : rows)
            r.metrics.erase(
                std::remove_if(r.metrics.begin(), r.metrics.end(), [&](const auto& v) { return v.first == m.name; }),
                r.metrics.end());
    }
    return rows;
}

namespace {

// What must agree between trials of one table: (name, its text in a trial, the swept keys that vary it).
struct Facet {
    std::string name;
    std::function<std::string(const TrialSummaryRow&)> value;
    std::vector<std::string> swept_by;
};

std::vector<Facet> facets(const std::vector<TrialSummaryRow>& trials) {
    std::vector<Facet> out{
        {"protocol", [](const TrialSummaryRow& t) { return t.protocol; }, {"protocol", "protocol.kind"}},
        {"explore_hours",
         [](const TrialSummaryRow& t) { return num(t.explore_hours); },
         {"protocol", "protocol.explore_hours"}},
        {"sample_hours",
         [](const TrialSummaryRow& t) { return num(t.sample_hours); },
         {"protocol", "protocol.sample_hours"}}};
    if (!trials.empty())
        for (std::size_t i = 0; i < trials.front().parameters.size(); ++i) {
            const std::string key = trials.front().parameters[i].first;
            out.push_back(
                {"analysis " + key,
                 [i](const TrialSummaryRow& t) { return i < t.parameters.size() ? t.parameters[i].second : ""; },
                 {"analysis", "analysis." + key}});
        }
    return out;
}

}  // namespace

std::string mixing_problem(const std::vector<TrialSummaryRow>& trials,
                           const std::vector<std::filesystem::path>& files) {
    // Appended, not "'" + ...: g++ 12 warns falsely on that (-Wrestrict, GCC bug 105329).
    const auto file = [&](std::size_t i) {
        std::string text = i < files.size() ? std::string("'") : std::string("trial ");
        text += i < files.size() ? files[i].string() + "'" : trials[i].name;
        return text;
    };
    for (const auto& f : facets(trials)) {
        const auto swept = [&](const TrialSummaryRow& t) {
            for (const auto& [k, v] : t.swept)
                if (std::find(f.swept_by.begin(), f.swept_by.end(), k) != f.swept_by.end()) return true;
            return false;
        };
        std::map<std::string, std::size_t> first_of_condition;  // condition -> first trial
        for (std::size_t i = 0; i < trials.size(); ++i) {
            // Trials of one condition always agree; across conditions unless a sweep varies it.
            const auto [it, fresh] = first_of_condition.emplace(trials[i].condition, i);
            const std::size_t j = swept(trials[i]) ? it->second : 0;
            if ((!fresh || j == 0) && f.value(trials[i]) != f.value(trials[j]))
                return "trials differ in " + f.name + ": " + f.value(trials[j]) + " in " + file(j) + ", " +
                       f.value(trials[i]) + " in " + file(i);
        }
    }
    return "";
}

std::vector<SummaryRow> summarize(const std::vector<TrialSummaryRow>& trials) {
    std::vector<SummaryRow> rows;
    std::map<std::string, std::vector<const TrialSummaryRow*>> by_condition;
    for (const auto& t : trials) {
        auto& members = by_condition[t.condition];
        if (members.empty()) {
            SummaryRow r;
            r.condition = t.condition;
            r.model = t.model;
            r.world = t.world;
            r.tilt_deg = t.tilt_deg;
            r.swept = t.swept;
            rows.push_back(r);
        }
        members.push_back(&t);
    }
    for (auto& r : rows) {
        const auto& members = by_condition[r.condition];
        r.n_seeds = static_cast<int>(members.size());
        for (std::size_t m = 0; m < members.front()->metrics.size(); ++m) {
            double sum = 0, sum2 = 0;
            for (const auto* t : members) sum += t->metrics[m].second;
            const double mean = sum / r.n_seeds;
            for (const auto* t : members) sum2 += (t->metrics[m].second - mean) * (t->metrics[m].second - mean);
            r.metric_names.push_back(members.front()->metrics[m].first);
            r.mean.push_back(mean);
            r.sd.push_back(r.n_seeds > 1 ? std::sqrt(sum2 / (r.n_seeds - 1)) : NAN);
        }
    }
    return rows;
}

void write_summary_csv(const std::filesystem::path& path, const std::vector<SummaryRow>& rows) {
    AtomicFile f(path);
    CsvWriter csv(f.stream());
    const auto keys = swept_keys(rows);
    csv.field("condition").field("model").field("world").field("tilt_deg");
    for (const auto& k : keys) csv.field("swept:" + k);
    csv.field("n_seeds");
    if (!rows.empty())
        for (const auto& m : rows.front().metric_names) csv.field(m + "_mean").field(m + "_sd");
    csv.end_row();
    for (const auto& r : rows) {
        csv.field(r.condition).field(r.model).field(r.world).field(r.tilt_deg);
        for (const auto& k : keys) csv.field(swept_value(r, k));
        csv.field(r.n_seeds);
        for (std::size_t m = 0; m < r.mean.size(); ++m) csv.field(r.mean[m]).field(r.sd[m]);
        csv.end_row();
    }
    f.commit();
}

void write_summary_markdown(const std::filesystem::path& path, const std::vector<SummaryRow>& rows) {
    AtomicFile f(path);
    auto& os = f.stream();
    auto keys = swept_keys(rows);
    const bool plain = keys.empty();  // the paper's layout: model and world
    if (plain) keys = {"model", "world"};
    os << '|';
    for (const auto& k : keys) os << ' ' << k << " |";
    std::vector<const analysis::Metric*> columns;
    for (const auto& m : analysis::metric_table()) {
        const bool reported =
            m.dims == 0 || std::any_of(rows.begin(), rows.end(), [&](const SummaryRow& r) {
                return std::find(r.metric_names.begin(), r.metric_names.end(), m.name) != r.metric_names.end();
            });
        if (m.digits >= 0 && reported) columns.push_back(&m);
    }
    os << " seeds |";
    for (const auto* c : columns) os << ' ' << c->heading << " |";
    os << "\n|";
    for (std::size_t i = 0; i < keys.size() + 1 + columns.size(); ++i) os << "---|";
    os << '\n';
    for (const auto& r : rows) {
        os << '|';
        for (const auto& k : keys)
            os << ' ' << (plain ? (k == "model" ? r.model : r.world) : swept_value(r, k)) << " |";
        os << ' ' << r.n_seeds << " |";
        for (const auto* c : columns) {
            const auto it = std::find(r.metric_names.begin(), r.metric_names.end(), c->name);
            const std::size_t m = static_cast<std::size_t>(it - r.metric_names.begin());
            const bool known = m < r.mean.size();
            os << ' ' << fixed(known ? r.mean[m] : NAN, c->digits);
            if (r.n_seeds > 1) os << " ± " << fixed(known ? r.sd[m] : NAN, c->digits);
            os << " |";
        }
        os << '\n';
    }
    // With one seed per condition a value is that trial's: no mean, no spread.
    const bool replicated = std::any_of(rows.begin(), rows.end(), [](const SummaryRow& r) { return r.n_seeds > 1; });
    os << (replicated ? "\nMean over seeds ± sample standard deviation (one seed: the trial's value)."
                      : "\nOne trial (seed) per condition: each value is that trial's.")
       << " MI: modality index (DBSCAN clusters per place cell);\n"
          "MSAI: mean spatial aliasing index; decoding: position error of the cosine-nearest rate-map bin.\n";
    if (std::any_of(columns.begin(), columns.end(), [](const analysis::Metric* c) { return c->dims == 3; }))
        os << "3-D (flying agents, 0.5 m voxels): isotropy = a single field's rate-weighted sd along z over the mean "
              "of\n"
              "its sds along x and y (1: round); vertical chance = the median vertical error of a random guess.\n";
    f.commit();
}

void write_trials_csv(const std::filesystem::path& path, const std::vector<TrialSummaryRow>& trials) {
    AtomicFile f(path);
    CsvWriter csv(f.stream());
    const auto keys = swept_keys(trials);
    csv.field("name").field("condition").field("model").field("world").field("tilt_deg");
    for (const auto& k : keys) csv.field("swept:" + k);
    csv.field("seed").field("protocol").field("explore_hours").field("sample_hours");
    if (!trials.empty())
        for (const auto& [name, v] : trials.front().metrics) csv.field(name);
    csv.end_row();
    for (const auto& t : trials) {
        csv.field(t.name).field(t.condition).field(t.model).field(t.world).field(t.tilt_deg);
        for (const auto& k : keys) csv.field(swept_value(t, k));
        csv.field(t.seed).field(t.protocol).field(t.explore_hours).field(t.sample_hours);
        for (const auto& [name, v] : t.metrics) csv.field(v);
        csv.end_row();
    }
    f.commit();
}

}  // namespace bvc3d
