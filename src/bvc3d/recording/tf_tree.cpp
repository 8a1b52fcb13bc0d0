#include "bvc3d/recording/tf_tree.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bvc3d/core/error.hpp"

namespace bvc3d::recording {

namespace {

std::string time_text(double t) {
    char s[40];
    std::snprintf(s, sizeof s, "%.9g s", t);
    return s;
}

}  // namespace

void TfTree::add(const StampedTransform& t, bool is_static) {
    const std::string child(bare_frame(t.child)), parent(bare_frame(t.parent));
    if (child.empty() || parent.empty())
        throw InputError("a tf transform at " + time_text(t.stamp) + " has an empty frame name (parent '" + parent +
                         "', child '" + child + "')");
    if (child == parent) throw InputError("a tf transform links frame '" + child + "' to itself");
    if (!std::isfinite(t.stamp) || !t.translation.allFinite())
        throw InputError("the tf transform " + parent + " → " + child + " at " + time_text(t.stamp) +
                         " has a non-finite value");
    Sample s{t.stamp, t.translation, checked_rotation(t.rotation)};
    auto [it, fresh] = links_.try_emplace(child);
    Link& link = it->second;
    if (fresh) {
        link.parent = parent;
        link.is_static = is_static;
    } else if (link.parent != parent) {
        throw InputError("frame '" + child + "' has two parents in tf: '" + link.parent + "' and '" + parent + "'");
    } else if (link.is_static != is_static) {
        throw InputError("the tf link " + parent + " → " + child + " is both static and dynamic");
    }
    if (is_static) {
        link.samples.assign(1, s);  // the latest static transform holds
        return;
    }
    if (link.samples.empty() || link.samples.back().stamp < s.stamp) {
        link.samples.push_back(s);
        return;
    }
    auto at = std::upper_bound(link.samples.begin(), link.samples.end(), s.stamp,
                               [](double v, const Sample& x) { return v < x.stamp; });
    if (at != link.samples.begin() && (at - 1)->stamp == s.stamp) *(at - 1) = s;  // a repeat replaces
    else link.samples.insert(at, s);
}

Eigen::Isometry3d TfTree::at(const std::string& child, const Link& link, double time, double tolerance,
                             bool hold_ends) const {
    const auto& v = link.samples;
    const auto make = [](const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
        Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
        m.linear() = q.toRotationMatrix();
        m.translation() = p;
        return m;
    };
    if (link.is_static) return make(v.front().translation, v.front().rotation);
    const std::string name = "the tf link " + link.parent + " → " + child;
    const auto after =
        std::lower_bound(v.begin(), v.end(), time, [](const Sample& x, double t) { return x.stamp < t; });
    if (after != v.end() && after->stamp == time) return make(after->translation, after->rotation);
    if (after == v.begin()) {
        if (after->stamp - time > tolerance)
            throw InputError(name + " starts at " + time_text(after->stamp) + ", " + time_text(after->stamp - time) +
                             " after the time " + time_text(time) + " (tf tolerance " + time_text(tolerance) + ")");
        return make(after->translation, after->rotation);
    }
    const Sample& a = *(after - 1);
    if (after == v.end()) {
        if (time - a.stamp > tolerance || !hold_ends)
            throw InputError(name + " ends at " + time_text(a.stamp) + ", " + time_text(time - a.stamp) +
                             " before the time " + time_text(time) + " (tf tolerance " + time_text(tolerance) + ")");
        return make(a.translation, a.rotation);
    }
    const Sample& b = *after;
    const double gap = b.stamp - a.stamp;
    if (gap > tolerance)
        throw InputError(name + " has a gap of " + time_text(gap) + " (from " + time_text(a.stamp) + " to " +
                         time_text(b.stamp) + ") around the time " + time_text(time) + ", more than the tf tolerance " +
                         time_text(tolerance));
    const double s = (time - a.stamp) / gap;
    return make(a.translation + s * (b.translation - a.translation), a.rotation.slerp(s, b.rotation));
}

Eigen::Isometry3d TfTree::lookup(const std::string& fixed_frame, const std::string& frame_name, double time,
                                 double tolerance, bool hold_ends) const {
    const std::string fixed(bare_frame(fixed_frame)), frame(bare_frame(frame_name));
    Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
    std::string current = frame, chain = frame;
    for (std::size_t hops = 0; current != fixed; ++hops) {
        const auto link = links_.find(current);
        if (link == links_.end() || hops > links_.size())
            throw InputError("tf has no chain from frame '" + fixed + "' to frame '" + frame + "' (" + chain +
                             (link == links_.end() ? " has no parent)" : " loops)"));
        m = at(current, link->second, time, tolerance, hold_ends) * m;
        current = link->second.parent;
        chain += " → " + current;
    }
    return m;
}

void TfTree::forget_before(double time) {
    for (auto& [child, link] : links_) {
        if (link.is_static) continue;
        auto& v = link.samples;
        const auto first =
            std::lower_bound(v.begin(), v.end(), time, [](const Sample& x, double t) { return x.stamp < t; });
        if (first - v.begin() > 1) v.erase(v.begin(), first - 1);
    }
}

}  // namespace bvc3d::recording
